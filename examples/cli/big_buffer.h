// Large buffers for the tool: the file image, the points, the library's workspace, the
// triangles.
//
// A fresh buffer of many megabytes costs a page fault per 4 KiB page on first touch, about
// 2.5 microseconds each on the 2-core VM of docs/benchmarks.md: 60 ms for a 100 MB
// workspace. Two ways around it, each for its own use (Linux; elsewhere, and below a
// megabyte, plain malloc):
// - Pages::huge maps the buffer aligned to 2 MiB and marked for transparent huge pages
//   (madvise mode), so the kernel fills it 2 MiB at a time, on first touch, only where it
//   is used. Fast where the kernel has such pages at hand; on a VM that hands its free
//   memory back to the host (free page reporting) a fresh huge page can cost more than its
//   512 small ones: measure before using it.
// - Pages::prefaulted maps small pages and faults them all in at once
//   (MADV_POPULATE_WRITE), about a quarter cheaper than one fault per page: for a buffer
//   about to be written whole, such as a file image.
#ifndef STRATMESH_CLI_BIG_BUFFER_H
#define STRATMESH_CLI_BIG_BUFFER_H

#include <cstddef>

namespace stratmesh_cli {

enum class Pages { huge, prefaulted };

// Uninitialised memory of `bytes` bytes (at least one), aligned for any type, or null.
void* allocate_big(size_t bytes, Pages pages = Pages::huge);

// Frees what allocate_big(bytes, ...) returned; `bytes` must be the same. Null is ignored.
void free_big(void* memory, size_t bytes);

// Faults in the pages of [memory, memory + bytes) in one call, for memory that another
// allocator gave (a std::vector's storage) and that is about to be written whole. Its
// content is kept. Only a hint: nothing on other systems or older kernels.
void prefault_pages(void* memory, size_t bytes);

// An owner of an allocate_big(..., Pages::prefaulted) buffer, for a file image.
class BigBuffer {
public:
    BigBuffer() = default;
    ~BigBuffer() { free_big(data_, size_); }
    BigBuffer(const BigBuffer&) = delete;
    BigBuffer& operator=(const BigBuffer&) = delete;

    // A new buffer of `bytes` bytes holding the first `keep` bytes of the old one; false
    // (the old one kept) if it cannot be allocated.
    bool reallocate(size_t bytes, size_t keep);
    char* data() const { return data_; }
    size_t size() const { return size_; }

private:
    char* data_ = nullptr;
    size_t size_ = 0;
};

} // namespace stratmesh_cli

#endif
