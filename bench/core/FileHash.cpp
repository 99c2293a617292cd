#include "core/FileHash.hpp"

#include <openssl/evp.h>

#include <fstream>
#include <memory>
#include <vector>

#include "core/Errors.hpp"

namespace avrbench {
namespace {

class Digest {
public:
    Digest() : ctx_(EVP_MD_CTX_new(), &EVP_MD_CTX_free) {
        if (!ctx_ || EVP_DigestInit_ex(ctx_.get(), EVP_sha256(), nullptr) != 1) throw std::runtime_error("sha256: init failed");
    }
    void update(const void* data, std::size_t size) { EVP_DigestUpdate(ctx_.get(), data, size); }
    std::string hex() {
        unsigned char out[EVP_MAX_MD_SIZE];
        unsigned int length = 0;
        EVP_DigestFinal_ex(ctx_.get(), out, &length);
        static const char* const kHex = "0123456789abcdef";
        std::string s;
        for (unsigned int i = 0; i < length; ++i) {
            s.push_back(kHex[out[i] >> 4]);
            s.push_back(kHex[out[i] & 15]);
        }
        return s;
    }

private:
    std::unique_ptr<EVP_MD_CTX, void (*)(EVP_MD_CTX*)> ctx_;
};

}  // namespace

std::string sha256_of_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw BadInput(path + ": cannot read");
    Digest d;
    std::vector<char> buffer(1 << 16);
    while (in) {
        in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
        d.update(buffer.data(), static_cast<std::size_t>(in.gcount()));
    }
    return d.hex();
}

std::string sha256_of_text(const std::string& text) {
    Digest d;
    d.update(text.data(), text.size());
    return d.hex();
}

}  // namespace avrbench
