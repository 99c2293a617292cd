#include "core/Notice.hpp"

#include <cstdio>
#include <mutex>
#include <set>

#include "core/ProcessHeap.hpp"

namespace avrbench {

namespace {

std::mutex& notice_mutex() {
    static std::mutex m;
    return m;
}

NoticeSink& current_sink() {
    static NoticeSink sink;
    return sink;
}

}  // namespace

void notice(const std::string& line) {
    NoticeSink sink;
    {
        const std::lock_guard<std::mutex> lock(notice_mutex());
        // A fuzzer loads its board once per input: say it once.
        // What was said stays said when a fuzz target restores its board.
        const OnProcessHeap outlives_the_board;
        static std::set<std::string> said;
        if (!said.insert(line).second) return;
        sink = current_sink();
    }
    if (sink) {
        sink(line);
    } else {
        std::fprintf(stderr, "avrbench: warning: %s\n", line.c_str());
    }
}

NoticeSink set_notice_sink(NoticeSink sink) {
    const std::lock_guard<std::mutex> lock(notice_mutex());
    NoticeSink previous = std::move(current_sink());
    current_sink() = std::move(sink);
    return previous;
}

}  // namespace avrbench
