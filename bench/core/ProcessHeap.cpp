#include "core/ProcessHeap.hpp"

namespace avrbench {

namespace {
thread_local int g_depth = 0;
}

int process_heap_depth() noexcept { return g_depth; }

OnProcessHeap::OnProcessHeap() noexcept { ++g_depth; }

OnProcessHeap::~OnProcessHeap() { --g_depth; }

}  // namespace avrbench
