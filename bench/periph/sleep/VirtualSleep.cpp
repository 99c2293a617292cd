// simavr's run loop already advances avr->cycle over a sleep to the next cycle
// timer; its raw sleep callback additionally usleep()s so the simulation keeps
// pace with the wall clock. A test bench must never wait on the wall clock.
#include "periph/Fixes.hpp"

namespace avrbench {
namespace {

void sleep_in_virtual_time(avr_t*, avr_cycle_count_t) {}

}  // namespace

std::unique_ptr<Fix> install_virtual_sleep(avr_t* avr) {
    avr->sleep = &sleep_in_virtual_time;
    return nullptr;
}

}  // namespace avrbench
