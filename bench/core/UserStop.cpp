#include "core/UserStop.hpp"

#include <atomic>
#include <csignal>

namespace avrbench {
namespace {

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "a signal handler may only touch lock-free atomics");

extern "C" void on_stop_signal(int) { g_stop.store(true, std::memory_order_relaxed); }

}  // namespace

void install_user_stop_handlers() {
    struct sigaction action {};
    action.sa_handler = &on_stop_signal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

bool user_stop_requested() { return g_stop.load(std::memory_order_relaxed); }
void request_user_stop() { g_stop.store(true, std::memory_order_relaxed); }

}  // namespace avrbench
