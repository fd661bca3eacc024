// Large buffers for the tool: the file image, the library's workspace, the triangles.
//
// A fresh buffer of many megabytes costs one page fault per 4 KiB page on first touch,
// and on a virtual machine a fault costs microseconds: the 170 MB workspace of a
// million-point cloud took about 0.1 s of faults. On Linux, allocate_big() maps the
// buffer itself, aligned to 2 MiB and marked for transparent huge pages (madvise mode), so
// the kernel fills it 2 MiB at a time: a fault per 512 pages. The pages are still touched
// first by whoever writes them (only what is used is paid for, by the thread that uses
// it). Elsewhere, and for small buffers, it is malloc.
#ifndef STRATMESH_CLI_BIG_BUFFER_H
#define STRATMESH_CLI_BIG_BUFFER_H

#include <cstddef>

namespace stratmesh_cli {

// Uninitialised memory of `bytes` bytes (at least one), aligned for any type, or null.
void* allocate_big(size_t bytes);

// Frees what allocate_big(bytes) returned; `bytes` must be the same. Null is ignored.
void free_big(void* memory, size_t bytes);

// Asks for huge pages on the whole 2 MiB blocks inside [memory, memory + bytes), memory
// that another allocator gave (a std::vector's storage). Only a hint: nothing on other
// systems, or if the kernel refuses.
void advise_huge_pages(void* memory, size_t bytes);

// An owner of an allocate_big() buffer.
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
