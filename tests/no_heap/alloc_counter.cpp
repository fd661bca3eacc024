// Counting replacements of every global allocation function, for the no-heap tests.
//
// How allocations are caught:
//   - glibc (and no sanitizer): malloc, calloc, realloc, free, aligned_alloc, posix_memalign
//     and memalign are replaced in the executable and forward to glibc's own entry points
//     (__libc_malloc, __libc_free, ...). This catches allocations that bypass operator new
//     (strdup, C library calls, a stray malloc in the library), so it is the stronger check.
//     Every operator new/new[]/delete/delete[] overload (plain, sized, aligned, nothrow) is
//     replaced too, on top of malloc/aligned_alloc, so an operator new is counted once.
//   - AddressSanitizer (or the thread, memory, hwaddress sanitizers): the sanitizer owns
//     malloc and operator new (replacing them collides with its runtime), so the counter
//     uses its allocation hooks instead, which see every allocation made through its
//     allocator, operator new included.
//   - any other C library: replacing malloc portably is fragile (no documented way to reach
//     the real one), so only the operator new/delete overloads are replaced and counted.
#include <cstddef>

#include <atomic>
#include <cstdlib>
#include <new>

// A sanitizer that owns malloc (address, thread, memory, hwaddress): use its hooks.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define NO_HEAP_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || \
    __has_feature(memory_sanitizer) || __has_feature(hwaddress_sanitizer)
#define NO_HEAP_ASAN 1
#endif
#endif

#if defined(NO_HEAP_ASAN)
#include <sanitizer/allocator_interface.h>
#endif

namespace {
std::atomic<std::size_t> g_allocations{0};
std::atomic<std::size_t> g_releases{0};
inline void count_allocation() { g_allocations.fetch_add(1, std::memory_order_relaxed); }
inline void count_release(const void* p) {
    if (p) g_releases.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

namespace alloc_counter {
std::size_t allocations();
std::size_t releases();
const char* mechanism();
std::size_t allocations() { return g_allocations.load(std::memory_order_relaxed); }
std::size_t releases() { return g_releases.load(std::memory_order_relaxed); }
}  // namespace alloc_counter

#if defined(NO_HEAP_ASAN)

namespace {
void on_malloc(const volatile void*, std::size_t) { count_allocation(); }
void on_free(const volatile void* p) { count_release(const_cast<const void*>(p)); }
struct InstallHooks {
    InstallHooks() { __sanitizer_install_malloc_and_free_hooks(on_malloc, on_free); }
} install_hooks;
}  // namespace

const char* alloc_counter::mechanism() { return "sanitizer hooks"; }

#else  // !NO_HEAP_ASAN

#if defined(__GLIBC__)
#define NO_HEAP_REPLACE_MALLOC 1

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* p, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
void __libc_free(void* p);

void* malloc(std::size_t size) noexcept {
    count_allocation();
    return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) noexcept {
    count_allocation();
    return __libc_calloc(count, size);
}
void* realloc(void* p, std::size_t size) noexcept {
    count_allocation();
    return __libc_realloc(p, size);
}
void free(void* p) noexcept {
    count_release(p);
    __libc_free(p);
}
void* memalign(std::size_t alignment, std::size_t size) noexcept {
    count_allocation();
    return __libc_memalign(alignment, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) noexcept {
    count_allocation();
    return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) noexcept {
    count_allocation();
    if (alignment < sizeof(void*) || (alignment & (alignment - 1)) != 0) return 22;  // EINVAL
    void* p = __libc_memalign(alignment, size);
    if (!p) return 12;  // ENOMEM
    *out = p;
    return 0;
}
}  // extern "C"

const char* alloc_counter::mechanism() { return "malloc+new"; }
#else
const char* alloc_counter::mechanism() { return "operator new only"; }
#endif

namespace {
void* allocate(std::size_t size) {
#if !defined(NO_HEAP_REPLACE_MALLOC)
    count_allocation();
#endif
    return std::malloc(size ? size : 1);
}
void* allocate_aligned(std::size_t size, std::align_val_t alignment) {
#if !defined(NO_HEAP_REPLACE_MALLOC)
    count_allocation();
#endif
    std::size_t a = static_cast<std::size_t>(alignment);
    if (a < sizeof(void*)) a = sizeof(void*);
    void* p = nullptr;
    if (posix_memalign(&p, a, size ? size : 1) != 0) return nullptr;
    return p;
}
void release(void* p) {
#if !defined(NO_HEAP_REPLACE_MALLOC)
    count_release(p);
#endif
    std::free(p);
}
[[noreturn]] void out_of_memory() {
#if defined(__cpp_exceptions)
    throw std::bad_alloc();
#else
    std::abort();
#endif
}
void* allocate_or_fail(std::size_t size) {
    void* p = allocate(size);
    if (!p) out_of_memory();
    return p;
}
void* allocate_aligned_or_fail(std::size_t size, std::align_val_t alignment) {
    void* p = allocate_aligned(size, alignment);
    if (!p) out_of_memory();
    return p;
}
}  // namespace

void* operator new(std::size_t size) { return allocate_or_fail(size); }
void* operator new[](std::size_t size) { return allocate_or_fail(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return allocate(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return allocate(size); }
void* operator new(std::size_t size, std::align_val_t a) { return allocate_aligned_or_fail(size, a); }
void* operator new[](std::size_t size, std::align_val_t a) { return allocate_aligned_or_fail(size, a); }
void* operator new(std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
    return allocate_aligned(size, a);
}
void* operator new[](std::size_t size, std::align_val_t a, const std::nothrow_t&) noexcept {
    return allocate_aligned(size, a);
}

void operator delete(void* p) noexcept { release(p); }
void operator delete[](void* p) noexcept { release(p); }
void operator delete(void* p, std::size_t) noexcept { release(p); }
void operator delete[](void* p, std::size_t) noexcept { release(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { release(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { release(p); }
void operator delete(void* p, std::align_val_t) noexcept { release(p); }
void operator delete[](void* p, std::align_val_t) noexcept { release(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { release(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { release(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { release(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { release(p); }

#endif  // NO_HEAP_ASAN
