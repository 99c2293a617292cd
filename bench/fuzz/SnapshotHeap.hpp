// The in-process fuzz targets' snapshot of a booted board: a heap of its own
// that every allocation the board makes goes to, copied once when the board
// is ready and written back after each input.
//
// Forking per input (the targets' other path, AVRBENCH_FUZZ_FORK=1) gave
// every input the booted board too, but cost a fork and a copy-on-write
// fault per page the input touched: most of each execution went to the
// kernel. Here the board (simavr's MCU structures, flash, RAM, EEPROM,
// peripherals, pending cycle timers and interrupts, the bench's parts, nets,
// host and recorders) lives in one reserved region at a fixed address, so a
// restore is a copy of bytes and every pointer in it stays right. Only the
// pages an input wrote are copied back: after each snapshot or restore the
// region is read-only, the first write to a page faults, and the handler
// notes the page and makes it writable (chaining any other fault to the
// handler that was there before).
//
// How allocations get there: this file's malloc, free, calloc, realloc,
// reallocarray and the aligned variants replace the C library's in the
// executable that links it (the fuzz targets only; glibc's "Replacing
// malloc"). A thread inside a Collecting scope allocates from the region;
// everything else (libFuzzer, AFL, other threads, OnProcessHeap scopes:
// core/ProcessHeap.hpp) from the C library's heap; free and realloc go by
// address. In sanitizer builds the sanitizer owns malloc: available() is
// false and the targets fork.
//
// What it cannot see: memory outside the region that the run changes.
// Process-wide caches grow on the process heap (OnProcessHeap) and keep
// what they learnt. A function-local static first reached by an input is
// made on the process heap too: this file also wraps the C++ runtime's
// __cxa_guard_acquire/release/abort, which bracket such an initialization,
// in an OnProcessHeap scope (else the next restore would take back memory
// the static still points at). Other lazily made process state (stdio
// buffers) is made by the targets' first input, which runs outside the
// region. The test SnapshotHeap.* checks restored runs against forked ones
// input by input.
#pragma once

#include <cstddef>

namespace avrbench::fuzz::snapshot_heap {

// False when a sanitizer (or anything else) owns malloc in this build.
bool available() noexcept;

// While one lives, this thread's allocations come from the region.
class Collecting {
public:
    Collecting() noexcept;
    ~Collecting();
    Collecting(const Collecting&) = delete;
    Collecting& operator=(const Collecting&) = delete;
};

// Copies the region's used part (the board as it is now) and starts
// watching writes. Once per process.
void take();

// Writes back the pages written since take() or the last restore(): the
// region is again what it was at take(). Nothing may still point into memory
// allocated since (call it after the input's objects are gone).
void restore();

// Whether `p` points into the region (memory a restore takes back).
bool holds(const void* p) noexcept;

// What the region held at take(), in bytes, and how many pages the last
// restore() wrote back.
std::size_t snapshot_bytes() noexcept;
std::size_t pages_restored() noexcept;

}  // namespace avrbench::fuzz::snapshot_heap
