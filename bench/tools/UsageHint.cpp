#include "tools/UsageHint.hpp"

#include <algorithm>
#include <vector>

namespace avrbench {

namespace {

// Levenshtein distance (insertions, deletions, substitutions).
std::size_t distance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diagonal = above;
        }
    }
    return row[b.size()];
}

// The nearest of `names` to `word`: within 2 edits, or 1 for short words.
std::string nearest(const std::string& word, const std::vector<std::string>& names) {
    std::string best;
    std::size_t best_distance = word.size() <= 4 ? 2 : 3;
    for (const auto& n : names) {
        const std::size_t d = distance(word, n);
        if (d < best_distance) {
            best = n;
            best_distance = d;
        }
    }
    return best;
}

}  // namespace

std::string usage_hint(CLI::App& app, int argc, char** argv) {
    // The deepest subcommand the parser entered, and the words after it.
    CLI::App* at = &app;
    int first = 1;
    for (int i = 1; i < argc; ++i) {
        bool entered = false;
        for (CLI::App* sub : at->get_subcommands({})) {
            if (sub->get_name() == argv[i]) {
                at = sub;
                first = i + 1;
                entered = true;
                break;
            }
        }
        if (!entered && at == &app) break;
    }
    if (at == &app || !at->get_subcommands({}).empty()) {
        // A subcommand was expected: the first word that is not an option.
        for (int i = first; i < argc; ++i) {
            const std::string word = argv[i];
            if (word.empty() || word[0] == '-') continue;
            std::vector<std::string> names;
            for (CLI::App* sub : at->get_subcommands({})) names.push_back(sub->get_name());
            const std::string near = nearest(word, names);
            if (!near.empty()) return "; did you mean '" + near + "'?";
            break;
        }
    }
    std::vector<std::string> options;
    for (const CLI::Option* o : at->get_options()) {
        for (const auto& l : o->get_lnames()) options.push_back("--" + l);
    }
    for (int i = first; i < argc; ++i) {
        std::string word = argv[i];
        if (word.rfind("--", 0) != 0) continue;
        word = word.substr(0, word.find('='));
        if (std::find(options.begin(), options.end(), word) != options.end()) continue;
        const std::string near = nearest(word, options);
        if (!near.empty()) return "; did you mean " + near + "?";
    }
    return {};
}

}  // namespace avrbench
