#include "SnapshotHeap.hpp"

#include <dlfcn.h>
#include <signal.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/ProcessHeap.hpp"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define AVRBENCH_SANITIZER_OWNS_MALLOC 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define AVRBENCH_SANITIZER_OWNS_MALLOC 1
#endif
#endif

extern "C" {
void* __libc_malloc(std::size_t size);
void __libc_free(void* p);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* p, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
}

namespace avrbench::fuzz::snapshot_heap {

namespace {

// Reserved, not committed: pages exist once written. A board of five MCUs
// with its recorders takes a few MiB; 4 GiB leaves room for any input.
constexpr std::size_t kRegionBytes = std::size_t{4} << 30;
constexpr std::size_t kPageBytes = 4096;
constexpr std::size_t kHeaderBytes = 16;  // before each block: its capacity, a check word
constexpr std::uint64_t kBlockMagic = 0x61766268'65617021ull;  // "avbheap!"

// Size classes: 16, 32, 48, 64 bytes, then four per power of two (80, 96,
// 112, 128, 160, ...), so a block wastes at most a fifth of itself.
constexpr std::size_t kClasses = 4 + 4 * 27;

std::size_t class_of(std::size_t bytes) {
    if (bytes <= 64) return bytes == 0 ? 0 : (bytes - 1) / 16;
    const unsigned k = 63u - static_cast<unsigned>(__builtin_clzll(bytes - 1));  // 2^k < bytes <= 2^(k+1)
    const std::size_t step = std::size_t{1} << (k - 2);
    return 4 + (k - 6) * 4 + (bytes - 1 - (std::size_t{1} << k)) / step;
}

std::size_t class_capacity(std::size_t c) {
    if (c < 4) return (c + 1) * 16;
    const std::size_t k = 6 + (c - 4) / 4;
    return (std::size_t{1} << k) + ((c - 4) % 4 + 1) * (std::size_t{1} << (k - 2));
}

struct BlockHeader {
    std::uint64_t capacity;
    std::uint64_t magic;
};

struct FreeBlock {
    FreeBlock* next;
};

// The allocator's own state, at the region's start, so a restore rewinds it
// with the blocks.
struct Bookkeeping {
    std::size_t used_bytes;  // from the region's start, this included
    FreeBlock* free_lists[kClasses];
};

char* g_region = nullptr;
thread_local int g_collecting = 0;

// The snapshot: the region's first g_saved_pages pages as they were.
char* g_saved = nullptr;
std::size_t g_saved_pages = 0;
std::size_t g_snapshot_bytes = 0;
// Pages written since: indexes, filled by the fault handler.
std::size_t* g_dirty = nullptr;
volatile std::size_t g_dirty_count = 0;
std::size_t g_pages_restored = 0;
// Pages nearly every input writes (the MCU's RAM, the cycle counter, the
// allocator's lists) are "hot": left writable and copied back on every
// restore, which costs less than a fault and two mprotect calls (each of
// which splits or merges the mapping) per page per input. A page becomes hot
// once it has been written by kHotAfterInputs inputs.
constexpr std::uint8_t kHotAfterInputs = 4;
std::uint8_t* g_times_dirty = nullptr;  // per snapshot page, up to kHotAfterInputs
std::size_t* g_hot = nullptr;
std::size_t g_hot_count = 0;
struct sigaction g_previous_segv {};
using UsableSize = std::size_t (*)(void*);
UsableSize g_libc_usable_size = nullptr;

[[noreturn]] void die(const char* what) {
    static const char prefix[] = "avrbench snapshot heap: ";
    (void)!::write(2, prefix, sizeof prefix - 1);
    (void)!::write(2, what, std::strlen(what));
    (void)!::write(2, "\n", 1);
    std::abort();
}

[[maybe_unused]] bool in_region(const void* p) {
    return g_region != nullptr && static_cast<const char*>(p) >= g_region &&
           static_cast<const char*>(p) < g_region + kRegionBytes;
}

Bookkeeping& books() { return *reinterpret_cast<Bookkeeping*>(g_region); }

void reserve_region() {
    if (g_region != nullptr) return;
    void* region = ::mmap(nullptr, kRegionBytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (region == MAP_FAILED) die("cannot reserve the region (mmap)");
    g_region = static_cast<char*>(region);
    books().used_bytes = (sizeof(Bookkeeping) + 15) / 16 * 16;
}

[[maybe_unused]] bool collecting() { return g_collecting > 0 && process_heap_depth() == 0; }

[[maybe_unused]] BlockHeader* header_of(void* p) {
    auto* header = reinterpret_cast<BlockHeader*>(static_cast<char*>(p) - kHeaderBytes);
    if (header->magic != kBlockMagic) die("free or realloc of a pointer the region never gave out");
    return header;
}

// A block of at least `bytes`, its start a multiple of `alignment` (>= 16).
[[maybe_unused]] void* region_allocate(std::size_t bytes, std::size_t alignment) {
    const std::size_t c = class_of(bytes);
    if (c >= kClasses) {
        errno = ENOMEM;
        return nullptr;
    }
    Bookkeeping& b = books();
    if (alignment <= 16 && b.free_lists[c] != nullptr) {
        FreeBlock* block = b.free_lists[c];
        b.free_lists[c] = block->next;
        header_of(block);
        return block;
    }
    const std::size_t capacity = class_capacity(c);
    std::size_t start = b.used_bytes + kHeaderBytes;
    start = (start + alignment - 1) / alignment * alignment;
    if (start + capacity > kRegionBytes) {
        errno = ENOMEM;
        return nullptr;
    }
    b.used_bytes = start + capacity;
    auto* header = reinterpret_cast<BlockHeader*>(g_region + start - kHeaderBytes);
    header->capacity = capacity;
    header->magic = kBlockMagic;
    return g_region + start;
}

[[maybe_unused]] void region_free(void* p) {
    BlockHeader* header = header_of(p);
    const std::size_t c = class_of(header->capacity);
    auto* block = static_cast<FreeBlock*>(p);
    block->next = books().free_lists[c];
    books().free_lists[c] = block;
}

[[maybe_unused]] std::size_t libc_usable_size(void* p) {
    if (g_libc_usable_size == nullptr) {
        g_libc_usable_size = reinterpret_cast<UsableSize>(::dlsym(RTLD_NEXT, "malloc_usable_size"));
        if (g_libc_usable_size == nullptr) die("the C library's malloc_usable_size is not there");
    }
    return g_libc_usable_size(p);
}

[[maybe_unused]] void* allocate(std::size_t bytes, std::size_t alignment) {
    if (collecting()) {
        if (g_region == nullptr) reserve_region();
        return region_allocate(bytes, alignment < 16 ? 16 : alignment);
    }
    return alignment <= 16 ? __libc_malloc(bytes) : __libc_memalign(alignment, bytes);
}

void on_segv(int signal, siginfo_t* info, void* context) {
    char* address = static_cast<char*>(info->si_addr);
    if (g_saved != nullptr && address >= g_region && address < g_region + g_saved_pages * kPageBytes) {
        const std::size_t page = static_cast<std::size_t>(address - g_region) / kPageBytes;
        if (::mprotect(g_region + page * kPageBytes, kPageBytes, PROT_READ | PROT_WRITE) != 0) die("mprotect");
        g_dirty[g_dirty_count] = page;
        g_dirty_count = g_dirty_count + 1;
        return;
    }
    // Not ours: whoever handled it before (libFuzzer's crash report), or the default.
    if ((g_previous_segv.sa_flags & SA_SIGINFO) != 0 && g_previous_segv.sa_sigaction != nullptr) {
        g_previous_segv.sa_sigaction(signal, info, context);
        return;
    }
    if (g_previous_segv.sa_handler != SIG_DFL && g_previous_segv.sa_handler != SIG_IGN &&
        g_previous_segv.sa_handler != nullptr) {
        g_previous_segv.sa_handler(signal);
        return;
    }
    // libFuzzer installs its handler after ours and calls ours first (its
    // "upstream"), never reporting the fault itself: say what it was, then
    // die of it (returning re-runs the access, which now kills) - the
    // engine sees a crash (AFL++ keeps the input; libFuzzer's parent, with
    // --jobs, too).
    static const char message[] = "avrbench: SIGSEGV outside the fuzz target's snapshot region: the bench crashed on this input\n";
    (void)!::write(2, message, sizeof message - 1);
    ::signal(SIGSEGV, SIG_DFL);
}

void watch_writes() {
    if (::mprotect(g_region, g_saved_pages * kPageBytes, PROT_READ) != 0) die("mprotect");
}

}  // namespace

bool available() noexcept {
#ifdef AVRBENCH_SANITIZER_OWNS_MALLOC
    return false;
#else
    return true;
#endif
}

Collecting::Collecting() noexcept { ++g_collecting; }

Collecting::~Collecting() { --g_collecting; }

void take() {
    if (!available()) die("take() in a build whose malloc is a sanitizer's");
    if (g_saved != nullptr) die("take() twice");
    reserve_region();
    (void)libc_usable_size(nullptr);  // resolved now, not inside the fault handler's reach
    g_snapshot_bytes = books().used_bytes;
    g_saved_pages = (g_snapshot_bytes + kPageBytes - 1) / kPageBytes;
    const OnProcessHeap outside;
    g_saved = static_cast<char*>(__libc_malloc(g_saved_pages * kPageBytes));
    g_dirty = static_cast<std::size_t*>(__libc_malloc(g_saved_pages * sizeof(std::size_t)));
    g_hot = static_cast<std::size_t*>(__libc_malloc(g_saved_pages * sizeof(std::size_t)));
    g_times_dirty = static_cast<std::uint8_t*>(__libc_calloc(g_saved_pages, 1));
    if (g_saved == nullptr || g_dirty == nullptr || g_hot == nullptr || g_times_dirty == nullptr) {
        die("no memory for the snapshot");
    }
    std::memcpy(g_saved, g_region, g_saved_pages * kPageBytes);
    struct sigaction action {};
    action.sa_sigaction = on_segv;
    action.sa_flags = SA_SIGINFO | SA_NODEFER;
    sigemptyset(&action.sa_mask);
    if (::sigaction(SIGSEGV, &action, &g_previous_segv) != 0) die("sigaction");
    g_dirty_count = 0;
    watch_writes();
}

void restore() {
    if (g_saved == nullptr) die("restore() before take()");
    for (std::size_t i = 0; i < g_hot_count; ++i) {
        const std::size_t offset = g_hot[i] * kPageBytes;
        std::memcpy(g_region + offset, g_saved + offset, kPageBytes);
    }
    const std::size_t count = g_dirty_count;
    for (std::size_t i = 0; i < count; ++i) {
        const std::size_t page = g_dirty[i];
        const std::size_t offset = page * kPageBytes;
        std::memcpy(g_region + offset, g_saved + offset, kPageBytes);
        if (++g_times_dirty[page] >= kHotAfterInputs) {
            g_hot[g_hot_count++] = page;  // stays writable
        } else if (::mprotect(g_region + offset, kPageBytes, PROT_READ) != 0) {
            die("mprotect");
        }
    }
    g_pages_restored = g_hot_count + count;
    g_dirty_count = 0;
}

bool holds(const void* p) noexcept { return in_region(p); }

std::size_t snapshot_bytes() noexcept { return g_snapshot_bytes; }

std::size_t pages_restored() noexcept { return g_pages_restored; }

// The C library's allocation functions, replaced in this executable.
namespace {

[[maybe_unused]] void* checked_aligned(std::size_t alignment, std::size_t bytes) {
    if (alignment == 0 || (alignment & (alignment - 1)) != 0) {
        errno = EINVAL;
        return nullptr;
    }
    return allocate(bytes, alignment);
}

}  // namespace

}  // namespace avrbench::fuzz::snapshot_heap

#ifndef AVRBENCH_SANITIZER_OWNS_MALLOC
namespace heap = avrbench::fuzz::snapshot_heap;

// A function-local static's initialization, bracketed by the C++ runtime's
// guard calls (Itanium C++ ABI 3.3.2), runs on the process heap: the static
// outlives every restore. The runtime's own functions do the guarding.
namespace {
using GuardAcquire = int (*)(std::uint64_t*);
using GuardDone = void (*)(std::uint64_t*);
GuardAcquire g_guard_acquire = nullptr;
GuardDone g_guard_release = nullptr;
GuardDone g_guard_abort = nullptr;

template <class F>
F runtime_function(F& cached, const char* name) {
    if (cached == nullptr) {
        cached = reinterpret_cast<F>(::dlsym(RTLD_NEXT, name));
        if (cached == nullptr) heap::die("the C++ runtime's guard functions are not there");
    }
    return cached;
}
}  // namespace

extern "C" {

void* malloc(std::size_t bytes) { return heap::allocate(bytes, 16); }

void free(void* p) {
    if (p == nullptr) return;
    if (heap::in_region(p)) {
        heap::region_free(p);
    } else {
        __libc_free(p);
    }
}

void* calloc(std::size_t count, std::size_t size) {
    if (!heap::collecting()) return __libc_calloc(count, size);
    std::size_t bytes = 0;
    if (__builtin_mul_overflow(count, size, &bytes)) {
        errno = ENOMEM;
        return nullptr;
    }
    void* p = heap::allocate(bytes, 16);
    if (p != nullptr) std::memset(p, 0, bytes);
    return p;
}

void* realloc(void* p, std::size_t bytes) {
    if (p == nullptr) return malloc(bytes);
    if (!heap::in_region(p)) return __libc_realloc(p, bytes);  // stays where it was made
    if (bytes == 0) {
        free(p);
        return nullptr;
    }
    const std::size_t capacity = heap::header_of(p)->capacity;
    if (bytes <= capacity) return p;
    void* moved = heap::allocate(bytes, 16);
    if (moved == nullptr) return nullptr;
    std::memcpy(moved, p, capacity);
    free(p);
    return moved;
}

// glibc's own reallocarray would hand a region block to its realloc.
void* reallocarray(void* p, std::size_t count, std::size_t size) {
    std::size_t bytes = 0;
    if (__builtin_mul_overflow(count, size, &bytes)) {
        errno = ENOMEM;
        return nullptr;
    }
    return realloc(p, bytes);
}

void* memalign(std::size_t alignment, std::size_t bytes) { return heap::checked_aligned(alignment, bytes); }

void* aligned_alloc(std::size_t alignment, std::size_t bytes) { return heap::checked_aligned(alignment, bytes); }

int posix_memalign(void** out, std::size_t alignment, std::size_t bytes) {
    if (alignment < sizeof(void*)) return EINVAL;
    void* p = heap::checked_aligned(alignment, bytes);
    if (p == nullptr) return errno == EINVAL ? EINVAL : ENOMEM;
    *out = p;
    return 0;
}

void* valloc(std::size_t bytes) { return heap::checked_aligned(heap::kPageBytes, bytes); }

void* pvalloc(std::size_t bytes) {
    return heap::checked_aligned(heap::kPageBytes, (bytes + heap::kPageBytes - 1) / heap::kPageBytes * heap::kPageBytes);
}

std::size_t malloc_usable_size(void* p) {
    if (p == nullptr) return 0;
    if (heap::in_region(p)) return heap::header_of(p)->capacity;
    return heap::libc_usable_size(p);
}

int __cxa_guard_acquire(std::uint64_t* guard) {
    const int initialize = runtime_function(g_guard_acquire, "__cxa_guard_acquire")(guard);
    if (initialize != 0) avrbench::enter_process_heap();
    return initialize;
}

void __cxa_guard_release(std::uint64_t* guard) {
    runtime_function(g_guard_release, "__cxa_guard_release")(guard);
    avrbench::leave_process_heap();
}

void __cxa_guard_abort(std::uint64_t* guard) {
    runtime_function(g_guard_abort, "__cxa_guard_abort")(guard);
    avrbench::leave_process_heap();
}

}  // extern "C"
#endif
