#include "core/ProcessHeap.hpp"

namespace avrbench {

namespace {
thread_local int g_depth = 0;
}

int process_heap_depth() noexcept { return g_depth; }

void enter_process_heap() noexcept { ++g_depth; }

void leave_process_heap() noexcept { --g_depth; }

OnProcessHeap::OnProcessHeap() noexcept { enter_process_heap(); }

OnProcessHeap::~OnProcessHeap() { leave_process_heap(); }

}  // namespace avrbench
