#include "big_buffer.h"

#include <cstdint>
#include <cstdlib>
#include <cstring>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace stratmesh_cli {

namespace {

// Below this, malloc: a mapping of its own would cost more than the faults it saves.
constexpr size_t kMapFrom = size_t{1} << 20;
constexpr size_t kHugePage = size_t{2} << 20;
constexpr size_t kSmallPage = 4096;

bool mapped(size_t bytes) {
#ifdef __linux__
    return bytes >= kMapFrom && bytes <= SIZE_MAX - 2 * kHugePage;
#else
    (void)bytes;
    return false;
#endif
}

// Whole huge pages, so that the last one can be a huge page too.
size_t mapped_length(size_t bytes) { return (bytes + kHugePage - 1) / kHugePage * kHugePage; }

} // namespace

void* allocate_big(size_t bytes, Pages pages) {
    if (bytes == 0) bytes = 1;
#ifdef __linux__
    if (mapped(bytes)) {
        const size_t length = mapped_length(bytes);
        // One huge page more than needed, to cut an aligned run out of it.
        void* raw = mmap(nullptr, length + kHugePage, PROT_READ | PROT_WRITE,
                         MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        if (raw == MAP_FAILED) return nullptr;
        const uintptr_t start = reinterpret_cast<uintptr_t>(raw);
        const uintptr_t aligned = (start + kHugePage - 1) / kHugePage * kHugePage;
        const size_t head = aligned - start, tail = kHugePage - head;
        if (head > 0) munmap(raw, head);
        if (tail > 0) munmap(reinterpret_cast<char*>(aligned) + length, tail);
        void* memory = reinterpret_cast<void*>(aligned);
        if (pages == Pages::huge)
            madvise(memory, length, MADV_HUGEPAGE);
        else
            prefault_pages(memory, bytes);
        return memory;
    }
#endif
    (void)pages;
    return std::malloc(bytes);
}

void free_big(void* memory, size_t bytes) {
    if (!memory) return;
    if (bytes == 0) bytes = 1;
#ifdef __linux__
    if (mapped(bytes)) {
        munmap(memory, mapped_length(bytes));
        return;
    }
#endif
    std::free(memory);
}

void prefault_pages(void* memory, size_t bytes) {
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
    const uintptr_t start = reinterpret_cast<uintptr_t>(memory);
    if (bytes < kMapFrom || start > UINTPTR_MAX - bytes) return;
    const uintptr_t first = start / kSmallPage * kSmallPage;
    madvise(reinterpret_cast<void*>(first), static_cast<size_t>(start + bytes - first),
            MADV_POPULATE_WRITE);
#else
    (void)memory;
    (void)bytes;
#endif
}

bool BigBuffer::reallocate(size_t bytes, size_t keep) {
    char* fresh = static_cast<char*>(allocate_big(bytes, Pages::prefaulted));
    if (!fresh) return false;
    if (keep > bytes) keep = bytes;
    if (keep > size_) keep = size_;
    if (keep > 0) std::memcpy(fresh, data_, keep);
    free_big(data_, size_);
    data_ = fresh;
    size_ = bytes;
    return true;
}

} // namespace stratmesh_cli
