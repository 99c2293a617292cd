#include "core/UserStop.hpp"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <csignal>

namespace avrbench {
namespace {

std::atomic<bool> g_stop{false};
static_assert(std::atomic<bool>::is_always_lock_free, "a signal handler may only touch lock-free atomics");

extern "C" void on_stop_signal(int) { g_stop.store(true, std::memory_order_relaxed); }

std::atomic<bool (*)()> g_poll{nullptr};
std::atomic<std::int64_t> g_next_poll_ns{0};

}  // namespace

void install_user_stop_handlers() {
    struct sigaction action {};
    action.sa_handler = &on_stop_signal;
    sigemptyset(&action.sa_mask);
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

bool user_stop_requested() {
    if (g_stop.load(std::memory_order_relaxed)) return true;
    bool (*poll)() = g_poll.load(std::memory_order_relaxed);
    if (poll == nullptr) return false;
    const std::int64_t now =
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
    if (now < g_next_poll_ns.load(std::memory_order_relaxed)) return false;
    constexpr std::int64_t kEvery_ns = 20'000'000;  // 20 ms
    g_next_poll_ns.store(now + kEvery_ns, std::memory_order_relaxed);
    if (!poll()) return false;
    g_stop.store(true, std::memory_order_relaxed);
    return true;
}

void request_user_stop() { g_stop.store(true, std::memory_order_relaxed); }
void clear_user_stop() { g_stop.store(false, std::memory_order_relaxed); }
void set_user_stop_poll(bool (*poll)()) { g_poll.store(poll, std::memory_order_relaxed); }

}  // namespace avrbench
