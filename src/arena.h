// >>arena ================================================================================
// The bump allocator over the caller's workspace.
//
// A bump allocator over the caller's buffer. A "measuring" arena (null base) only adds up
// sizes, so *_workspace_size() runs the very allocation sequence the real call runs and
// the two cannot disagree.

namespace stratmesh {
namespace detail {

struct Arena {
    static const size_t kAlign = 16;

    unsigned char* base;
    size_t capacity;
    size_t used;
    size_t high_water;
    bool failed;
    size_t pad;  // bytes skipped at the start of the caller's buffer to align `base`

    static Arena over(void* buffer, size_t bytes) {
        Arena a = {nullptr, 0, 0, 0, false, 0};
        if (!buffer) return a;
        uintptr_t start = reinterpret_cast<uintptr_t>(buffer);
        a.pad = (kAlign - start % kAlign) % kAlign;
        if (bytes < a.pad) {
            a.base = static_cast<unsigned char*>(buffer);
            return a;
        }
        a.base = static_cast<unsigned char*>(buffer) + a.pad;
        a.capacity = bytes - a.pad;
        return a;
    }
    static Arena measuring() { return Arena{nullptr, SIZE_MAX, 0, 0, false, 0}; }

    // The peak, counted from the start of the caller's buffer: a buffer of this size at
    // the same address would have been enough.
    size_t peak_from_buffer() const { return high_water ? pad + high_water : 0; }

    bool is_measuring() const { return base == nullptr && capacity == SIZE_MAX; }

    // The bytes to ask the caller for: what was used, plus the worst alignment padding.
    size_t required_bytes() const { return high_water + kAlign - 1; }

    template <class T> T* alloc(size_t count) { return static_cast<T*>(take(count, sizeof(T))); }

    // alloc's one body, whatever the type (one copy of the code, not one per type).
    void* take(size_t count, size_t size) {
        if (failed) return nullptr;
        if (count > (SIZE_MAX - kAlign) / size) {
            failed = true;
            return nullptr;
        }
        size_t bytes = (count * size + kAlign - 1) / kAlign * kAlign;
        if (bytes > capacity - used) {
            failed = true;
            return nullptr;
        }
        size_t offset = used;
        used += bytes;
        if (used > high_water) high_water = used;
        if (is_measuring()) return reinterpret_cast<void*>(kAlign);  // never dereferenced
        return base + offset;
    }

    size_t mark() const { return used; }
    void rewind(size_t m) { used = m; }

    // The last `bytes` of the buffer (aligned), if they lie above everything allocated so
    // far, for data that stays valid only while the arena does not reach it (see
    // untouched); null if there is no such room. Allocations may later take it.
    void* room_at_end(size_t bytes) const {
        if (is_measuring() || bytes > capacity - used) return nullptr;
        size_t offset = (capacity - bytes) / kAlign * kAlign;
        return offset >= used ? base + offset : nullptr;
    }
    // Whether the arena has never reached p (in room_at_end's room).
    bool untouched(const void* p) const {
        return static_cast<const unsigned char*>(p) >= base + high_water;
    }
};

// The caller's buffers as address ranges, so that arguments sharing memory are refused:
// the input is read while the workspace and outputs are written, and an overlap would
// corrupt the result silently. Empty buffers overlap nothing; lengths that would run past
// the end of the address space are cut there.
struct ByteRange {
    uintptr_t begin, end;
};

static inline size_t saturating_product(size_t a, size_t b) {
    return b != 0 && a > SIZE_MAX / b ? SIZE_MAX : a * b;
}

static inline ByteRange byte_range(const void* p, size_t bytes) {
    uintptr_t begin = reinterpret_cast<uintptr_t>(p);
    if (!p) return {0, 0};
    return {begin, bytes > UINTPTR_MAX - begin ? UINTPTR_MAX : begin + bytes};
}

// Bytes covered by `count` records `stride` apart whose last one is `record_bytes` long.
static inline ByteRange strided_range(const void* p, size_t count, size_t stride, size_t record_bytes) {
    if (count == 0) return {0, 0};
    size_t span = saturating_product(count - 1, stride);
    return byte_range(p, span > SIZE_MAX - record_bytes ? SIZE_MAX : span + record_bytes);
}

static inline bool ranges_overlap(ByteRange a, ByteRange b) {
    return a.begin < a.end && b.begin < b.end && a.begin < b.end && b.begin < a.end;
}

// True if any two of the `count` ranges overlap.
static inline bool any_overlap(const ByteRange* ranges, size_t count) {
    for (size_t i = 0; i < count; ++i)
        for (size_t j = i + 1; j < count; ++j)
            if (ranges_overlap(ranges[i], ranges[j])) return true;
    return false;
}

}  // namespace detail
}  // namespace stratmesh
