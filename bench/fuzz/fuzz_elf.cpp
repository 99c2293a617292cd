// The ELF loader on arbitrary bytes: BadInput or a loaded image, nothing else.
#include "mcu/ElfImage.hpp"
#include "core/Errors.hpp"
#include "FuzzInput.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    avrbench::fuzz::InputFile file(data, size, ".elf");
    try {
        const auto image = avrbench::ElfImage::load(file.path());
        (void)image.text_end_bytes();
        (void)image.ram_end_of_static_data();
        (void)image.describe_flash_address(0);
    } catch (const avrbench::BadInput&) {
    }
    return 0;
}
