// >>request ==============================================================================
// What one tube is asked for: axis, layers, ends, caps, origin, read once from Options.
//
// reconstruct() meshes several tubes where the cloud parts: the trunk, each branch, the
// one tube they are weighed against, and the samples the automatic axis is chosen on. Each
// has its own axis, layers, ends and caps; a TubeRequest says them, made once from the
// caller's Options (tube_request()), and each step asks for its tube with a request of its
// own. The caller's Options are only read: for the callbacks and the invalid points.

namespace stratmesh {
namespace detail {

// The layers asked for, first match wins (see Options::cuts): the cuts, else `count`
// equal layers, else layers of about `height`, else automatic.
struct LayerRequest {
    const double* cuts;
    size_t cut_count;
    uint32_t count;
    double height;
};

// What reconstruct() does where the cloud parts into branches (see PartCounts).
enum class PartsPolicy : uint32_t {
    compare,   // the parts joined where whole and smaller than one tube, else the one tube
    one_tube,  // one tube, without a search (the one_tube flag)
    keep,      // the parts, joined where they can be (the keep_parts flag)
};

struct TubeRequest {
    Axis axis;              // Axis::automatic until resolve_axis() chooses
    double direction[3];    // with Axis::direction
    LayerRequest layers;
    uint32_t cut_ends;      // ClosedEnd bits: the ends that are cuts, never closed ones
    bool caps;              // the boundary loops closed (close_ends)
    bool surface_flips;
    bool drop_outliers;     // the cloud is read without its outliers
    const double* origin;   // the frame's reference point, or null for the centroid
    PartsPolicy parts;
    // The caller's Options, whose callbacks run (progress only where `progress`), or null:
    // none (an axis trial).
    const Options* caller;
    bool progress;
};

inline TubeRequest tube_request(const Options& options) {
    const uint32_t f = options.flags;
    TubeRequest r = {};
    r.axis = options.axis;
    for (int k = 0; k < 3; ++k) r.direction[k] = options.direction[k];
    r.layers = {options.cuts, options.cut_count, options.layer_count, options.layer_height};
    r.cut_ends = (f & open_ends) ? closed_bottom | closed_top : 0u;
    r.caps = (f & close_ends) != 0;
    r.surface_flips = (f & surface_flips) != 0;
    r.drop_outliers = (f & drop_outliers) != 0;
    r.origin = (f & origin_given) ? options.origin : nullptr;
    r.parts = (f & one_tube) ? PartsPolicy::one_tube
              : (f & keep_parts) ? PartsPolicy::keep
                                 : PartsPolicy::compare;
    r.caller = &options;
    r.progress = true;
    return r;
}

// The same request along a direction.
inline TubeRequest along_direction(TubeRequest r, const double* direction) {
    r.axis = Axis::direction;
    for (int k = 0; k < 3; ++k) r.direction[k] = direction[k];
    return r;
}

const Options kNoCallbacks = {};

// The Options whose job runner a tube hands its jobs to (none in an axis trial).
inline const Options& jobs_of(const TubeRequest& request) {
    return request.caller ? *request.caller : kNoCallbacks;
}

inline void notify(const Options& options, Phase phase, double fraction);  // >>jobs

inline void notify(const TubeRequest& request, Phase phase, double fraction) {
    if (request.progress && request.caller) notify(*request.caller, phase, fraction);
}

}  // namespace detail
}  // namespace stratmesh
