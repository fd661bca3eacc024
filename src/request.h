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

// The layers asked for (see Options::cuts): the cuts, or `count` equal layers, or layers
// of about `height` (at most one of them: layer_choice_refusal()), else automatic.
struct LayerRequest {
    const double* cuts;
    size_t cut_count;
    uint32_t count;
    double height;
};

struct TubeRequest {
    Axis axis;              // Axis::automatic until resolve_axis() chooses
    double direction[3];    // with Axis::direction
    LayerRequest layers;
    uint32_t cut_ends;      // ClosedEnd bits: the ends that are cuts, never closed ones
    bool caps;              // the boundary loops closed (add_caps)
    bool surface_flips;
    bool drop_outliers;     // the cloud is read without its outliers
    const double* origin;   // the frame's reference point, or null for the centroid
    Parts parts;            // Parts::one_tube where this build cannot look for parts
    // The caller's Options: its job runner, or null for none (an axis trial).
    const Options* caller;
    // The Options whose progress callback is told, or null: none (a branch, whose progress
    // would run backwards from part to part; an axis trial).
    const Options* progress;
};

// The bits Flags defines: any other is refused.
const uint32_t kDefinedFlags =
    skip_invalid_points | add_caps | origin_given | drop_outliers | surface_flips | ends_are_cuts;

// Why a call that takes Options refuses them with invalid_argument, or null: a flag bit
// that Flags does not define, or a Parts value outside the enum.
static inline const char* options_refusal(const Options& options) {
    if (options.flags & ~kDefinedFlags) return "Options::flags has a bit that Flags does not define";
    if (static_cast<uint32_t>(options.parts) > static_cast<uint32_t>(Parts::apart))
        return "Options::parts is not a Parts value";
    return nullptr;
}

// Why reconstruct() and the stream refuse the layer options with invalid_argument, or
// null: more than one of the cuts, layer_count and layer_height is given, which would
// leave one of them unused.
static inline const char* layer_choice_refusal(const Options& options) {
    const int given = (options.cut_count > 0 ? 1 : 0) + (options.layer_count > 0 ? 1 : 0) +
                      (options.layer_height > 0 ? 1 : 0);
    return given > 1 ? "give at most one of Options::cuts, layer_count and layer_height" : nullptr;
}

static inline TubeRequest tube_request(const Options& options) {
    const uint32_t f = options.flags;
    return {options.axis,
            {options.direction[0], options.direction[1], options.direction[2]},
            {options.cuts, options.cut_count, options.layer_count, options.layer_height},
            kClosedEnds && (f & ends_are_cuts) ? closed_bottom | closed_top : 0u,
            (f & add_caps) != 0,
            kSurfaceFlips && (f & surface_flips),
            kDropOutliers && (f & drop_outliers),
            (f & origin_given) ? options.origin : nullptr,
            kFindParts ? options.parts : Parts::one_tube,
            &options,
            &options};
}

// Sets the request's axis to a direction.
static inline void set_direction(TubeRequest& request, const double* direction) {
    request.axis = Axis::direction;
    for (int k = 0; k < 3; ++k) request.direction[k] = direction[k];
}

const Options kNoCallbacks = {};

// The Options whose job runner a tube hands its jobs to (none in an axis trial).
static inline const Options& jobs_of(const TubeRequest& request) {
    return request.caller ? *request.caller : kNoCallbacks;
}

// Phase progress, to the caller's callback where the request reports progress.
static inline void notify(const TubeRequest& request, Phase phase, double fraction) {
    if (request.progress) notify(*request.progress, phase, fraction);
}

}  // namespace detail
}  // namespace stratmesh
