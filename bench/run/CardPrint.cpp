#include "run/CardPrint.hpp"

#include <algorithm>
#include <cctype>

namespace avrbench {

namespace {

std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front())) != 0) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back())) != 0) s.remove_suffix(1);
    return s;
}

std::string upper(std::string_view s) {
    std::string out(s);
    std::transform(out.begin(), out.end(), out.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    return out;
}

}  // namespace

std::optional<CardPrintCommand> card_print_command(std::string_view line) {
    line = trim(line);
    if (!line.empty() && (line.front() == 'N' || line.front() == 'n')) {
        std::size_t i = 1;
        while (i < line.size() && std::isdigit(static_cast<unsigned char>(line[i])) != 0) ++i;
        if (i == 1) return std::nullopt;
        line = trim(line.substr(i));
    }
    if (const std::size_t star = line.rfind('*'); star != std::string_view::npos) line = trim(line.substr(0, star));
    if (line.size() < 3 || (line[0] != 'M' && line[0] != 'm')) return std::nullopt;
    const std::string_view code = line.substr(1, 2);
    const std::string_view rest = line.substr(3);
    if (!rest.empty() && std::isspace(static_cast<unsigned char>(rest.front())) == 0) return std::nullopt;  // M240, M23.1
    if (code == "24") return CardPrintCommand{CardPrintCommand::Kind::Start, {}};
    if (code == "23" && !trim(rest).empty()) return CardPrintCommand{CardPrintCommand::Kind::Select, std::string(trim(rest))};
    return std::nullopt;
}

std::optional<std::string> card_file(const std::vector<const StoredFiles*>& cards, const std::string& file, std::string& why) {
    std::string wanted = upper(file);
    if (!wanted.empty() && wanted.front() == '/') wanted.erase(0, 1);
    bool readable = false;
    for (const StoredFiles* card : cards) {
        const auto files = card->stored_files();
        if (!files) continue;
        readable = true;
        for (const FatFile& f : *files) {
            if (upper(f.name) == wanted) return f.bytes;
        }
    }
    why = cards.empty() ? "prints from a card, and the board has none"
          : readable    ? "prints '" + file + "', which is on no card in the root directory"
                        : "prints from a card the bench cannot read (no card in the slot, or no FAT file system on it)";
    return std::nullopt;
}

}  // namespace avrbench
