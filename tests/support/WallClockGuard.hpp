// A wall-clock bound for tests that run simulations: a regression that makes
// a run loop spin must fail the test, not hang CI.
//
// run_guarded() runs `body` in a forked child and waits at most
// `limit_seconds` of wall time; past that it kills the child and reports a
// hang. The body returns "" for success or a failure message.
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <functional>
#include <string>
#include <thread>

namespace avrbench::test {

inline std::string run_guarded(double limit_seconds, const std::function<std::string()>& body) {
    int fds[2];
    if (::pipe(fds) != 0) return "pipe() failed";
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid < 0) return "fork() failed";
    if (pid == 0) {
        ::close(fds[0]);
        std::string message;
        try {
            message = body();
        } catch (const std::exception& e) {
            message = std::string("exception: ") + e.what();
        }
        std::size_t at = 0;
        while (at < message.size()) {
            const ssize_t n = ::write(fds[1], message.data() + at, message.size() - at);
            if (n <= 0) break;
            at += static_cast<std::size_t>(n);
        }
        ::_exit(message.empty() ? 0 : 1);
    }
    ::close(fds[1]);
    const auto start = std::chrono::steady_clock::now();
    int status = 0;
    for (;;) {
        const pid_t done = ::waitpid(pid, &status, WNOHANG);
        if (done == pid) break;
        if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() > limit_seconds) {
            ::kill(pid, SIGKILL);
            ::waitpid(pid, &status, 0);
            ::close(fds[0]);
            return "HANG: still running after " + std::to_string(limit_seconds) + " s of wall time (killed)";
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    std::string message;
    char buf[4096];
    ssize_t n;
    while ((n = ::read(fds[0], buf, sizeof buf)) > 0) message.append(buf, static_cast<std::size_t>(n));
    ::close(fds[0]);
    if (WIFSIGNALED(status)) return "the guarded body died of signal " + std::to_string(WTERMSIG(status));
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return message.empty() ? "the guarded body failed" : message;
    return "";
}

}  // namespace avrbench::test
