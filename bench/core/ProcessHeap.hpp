// Process-wide state that must outlive a restored board.
//
// The in-process fuzz targets (bench/fuzz/SnapshotHeap.hpp) put every
// allocation the board makes into a heap they snapshot once booted and
// rewind after each input. A cache that belongs to the process, not to the
// board (the notices already said, say), must not live there: the rewind
// would take its nodes back while the cache still points at them. Code that
// grows such a cache does it inside an OnProcessHeap scope, whose
// allocations go to the C library's heap whatever the snapshot heap does.
// Outside the fuzz targets the scope costs one thread-local increment.
#pragma once

namespace avrbench {

// How many OnProcessHeap scopes this thread is inside.
int process_heap_depth() noexcept;
// The same scope without an object, for code that cannot hold one across
// calls (the fuzz targets' hooks on function-local statics' initialization).
void enter_process_heap() noexcept;
void leave_process_heap() noexcept;

class OnProcessHeap {
public:
    OnProcessHeap() noexcept;
    ~OnProcessHeap();
    OnProcessHeap(const OnProcessHeap&) = delete;
    OnProcessHeap& operator=(const OnProcessHeap&) = delete;
};

}  // namespace avrbench
