// A person (Ctrl-C) or a CI system (SIGTERM on a timeout) asking a long run
// to stop. Run loops poll user_stop_requested() between slices of simulated
// time; the run then ends as if its time were up, writes what it recorded,
// and the CLI exits with 130 (128 + SIGINT, the shell convention).
#pragma once

namespace avrbench {

// Installs SIGINT and SIGTERM handlers that only set the flag (async-signal-safe).
void install_user_stop_handlers();
bool user_stop_requested();
void request_user_stop();  // what the handlers do; also for tests

}  // namespace avrbench
