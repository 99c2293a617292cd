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
void clear_user_stop();    // a front end that goes on after a stop (Python, between calls)

// A front end whose signals arrive elsewhere (Python's, handled by the
// interpreter) asks through `poll` whether to stop; user_stop_requested()
// calls it at most every 20 ms of wall time, so a long run notices within
// that. nullptr: none.
void set_user_stop_poll(bool (*poll)());

}  // namespace avrbench
