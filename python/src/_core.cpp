// stratmesh._core: the library bound for Python. numpy arrays are read in place, the GIL is
// released around every library call, and a failed status becomes stratmesh.Error.
#define STRATMESH_IMPLEMENTATION
#include "stratmesh.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <memory>
#include <new>
#include <string>
#include <thread>
#include <vector>

namespace py = pybind11;

namespace {

const char* status_name(stratmesh::Status status) {
    switch (status) {
#define STRATMESH_PY_NAME(name, message) \
    case stratmesh::Status::name: return #name;
        STRATMESH_STATUS_LIST(STRATMESH_PY_NAME)
#undef STRATMESH_PY_NAME
    }
    return "unknown";
}

const char* status_message(stratmesh::Status status) {
    switch (status) {
#define STRATMESH_PY_MESSAGE(name, message) \
    case stratmesh::Status::name: return message;
        STRATMESH_STATUS_LIST(STRATMESH_PY_MESSAGE)
#undef STRATMESH_PY_MESSAGE
    }
    return "unknown status";
}

// The Flags bits by their names in the header: the Python keywords and flags=(...) map
// onto this table, so a new flag needs one line here.
struct FlagName {
    const char* name;
    uint32_t bit;
};
const FlagName kFlags[] = {
    {"skip_invalid_points", stratmesh::skip_invalid_points},
    {"add_caps", stratmesh::add_caps},
    {"origin_given", stratmesh::origin_given},
    {"drop_outliers", stratmesh::drop_outliers},
    {"surface_flips", stratmesh::surface_flips},
    {"ends_are_cuts", stratmesh::ends_are_cuts},
};

// The Parts values by their names in the header (parts="...").
struct PartsName {
    const char* name;
    stratmesh::Parts parts;
};
const PartsName kParts[] = {
    {"automatic", stratmesh::Parts::automatic},
    {"one_tube", stratmesh::Parts::one_tube},
    {"apart", stratmesh::Parts::apart},
};

const char* phase_name(stratmesh::Phase phase) {
    switch (phase) {
        case stratmesh::Phase::validate: return "validate";
        case stratmesh::Phase::layers: return "layers";
        case stratmesh::Phase::triangulate: return "triangulate";
        case stratmesh::Phase::stitch: return "stitch";
        case stratmesh::Phase::manifold: return "manifold";
        case stratmesh::Phase::done: return "done";
    }
    return "unknown";
}

// Raises stratmesh.<type> (Error, or ArgumentTypeError for an argument of the wrong type).
[[noreturn]] void raise_as(const char* type, stratmesh::Status status, const char* detail,
                           py::object report) {
    py::object error = py::module_::import("stratmesh._error").attr(type)(
        status_name(status), status_message(status),
        detail ? py::object(py::str(detail)) : py::object(py::none()), report);
    PyErr_SetObject(reinterpret_cast<PyObject*>(Py_TYPE(error.ptr())), error.ptr());
    throw py::error_already_set();
}

[[noreturn]] void raise_error(stratmesh::Status status, const char* detail, py::object report) {
    raise_as("Error", status, detail, report);
}

[[noreturn]] void raise_argument(const std::string& detail) {
    raise_error(stratmesh::Status::invalid_argument, detail.c_str(), py::none());
}

[[noreturn]] void raise_wrong_type(const std::string& detail) {
    raise_as("ArgumentTypeError", stratmesh::Status::invalid_argument, detail.c_str(), py::none());
}

const char* parts_outcome_name(stratmesh::PartsOutcome outcome) {
    switch (outcome) {
        case stratmesh::PartsOutcome::one_tube: return "one_tube";
        case stratmesh::PartsOutcome::joined: return "joined";
        case stratmesh::PartsOutcome::kept_apart: return "kept_apart";
        case stratmesh::PartsOutcome::undone: return "undone";
    }
    return "unknown";
}

py::tuple triple(const double* v) { return py::make_tuple(v[0], v[1], v[2]); }

// The report as nested namespaces (report.points.used_count, ...): one place to extend
// when the header's Report grows a group.
py::object report_object(const stratmesh::Report& r, stratmesh::Status status) {
    py::object ns = py::module_::import("types").attr("SimpleNamespace");
    py::list layers;
    size_t shown = r.layers.info ? std::min(r.layers.used_count, r.layers.info_capacity) : 0;
    for (size_t i = 0; i < shown; ++i) {
        const stratmesh::LayerInfo& l = r.layers.info[i];
        layers.append(ns(py::arg("bottom") = l.bottom, py::arg("top") = l.top,
                         py::arg("centre") = py::make_tuple(l.centre[0], l.centre[1], l.centre[2]),
                         py::arg("radius") = l.radius, py::arg("point_count") = l.point_count,
                         py::arg("triangle_count") = l.triangle_count,
                         py::arg("fold_count") = l.fold_count,
                         py::arg("closed_ends") = l.closed_ends));
    }
    return ns(
        py::arg("status") = status_name(status),
        py::arg("triangle_count") = r.triangle_count,
        py::arg("axis") = py::make_tuple(r.axis[0], r.axis[1], r.axis[2]),
        py::arg("axis_origin") =
            py::make_tuple(r.axis_origin[0], r.axis_origin[1], r.axis_origin[2]),
        py::arg("points") = ns(
            py::arg("in_count") = r.points.in_count, py::arg("used_count") = r.points.used_count,
            py::arg("duplicate_count") = r.points.duplicate_count,
            py::arg("rejected_count") = r.points.rejected_count,
            py::arg("outlier_count") = r.points.outlier_count,
            py::arg("unused_count") = r.points.unused_count,
            py::arg("first_invalid_index") = r.points.first_invalid_index,
            py::arg("held_count") = r.points.held_count),
        py::arg("layers") = ns(
            py::arg("planned_count") = r.layers.planned_count,
            py::arg("used_count") = r.layers.used_count,
            py::arg("parallel_count") = r.layers.parallel_count,
            py::arg("skeleton_node_count") = r.layers.skeleton_node_count, py::arg("info") = layers),
        py::arg("caps") = ns(
            py::arg("closed_count") = r.caps.closed_count,
            py::arg("open_count") = r.caps.open_count,
            py::arg("triangle_count") = r.caps.triangle_count,
            py::arg("wall_flip_count") = r.caps.wall_flip_count),
        py::arg("parts") = ns(
            py::arg("outcome") = parts_outcome_name(r.parts.outcome),
            py::arg("part_count") = r.parts.part_count,
            py::arg("joined_side_count") = r.parts.joined_side_count,
            py::arg("apart_side_count") = r.parts.apart_side_count,
            py::arg("grafted_branch_count") = r.parts.grafted_branch_count,
            py::arg("junction_triangle_count") = r.parts.junction_triangle_count,
            py::arg("removed_triangle_count") = r.parts.removed_triangle_count,
            py::arg("gap") = r.parts.parting.gap,
            py::arg("above") = r.parts.parting.above,
            py::arg("above_branch_count") = r.parts.parting.above_branch_count,
            py::arg("below") = r.parts.parting.below,
            py::arg("below_branch_count") = r.parts.parting.below_branch_count),
        py::arg("diagnostics") = ns(
            py::arg("fold_count") = r.diagnostics.fold_count,
            py::arg("illegal_removed_count") = r.diagnostics.illegal_removed_count,
            py::arg("diagonal_swap_count") = r.diagnostics.diagonal_swap_count,
            py::arg("point_spacing") = r.diagnostics.point_spacing,
            py::arg("area_per_point") = r.diagnostics.area_per_point,
            py::arg("fit_sample_count") = r.diagnostics.fit_sample_count,
            py::arg("misfit_area_fraction") = r.diagnostics.misfit_area_fraction,
            py::arg("misfit_area") = r.diagnostics.misfit_area,
            py::arg("misfit_box_min") = triple(r.diagnostics.misfit_box_min),
            py::arg("misfit_box_max") = triple(r.diagnostics.misfit_box_max),
            py::arg("crossing_pair_count") = r.diagnostics.crossing_pair_count,
            py::arg("crossing_check_complete") = r.diagnostics.crossing_check_complete,
            py::arg("crossing_box_min") = triple(r.diagnostics.crossing_box_min),
            py::arg("crossing_box_max") = triple(r.diagnostics.crossing_box_max)),
        py::arg("detail") = r.detail ? py::object(py::str(r.detail)) : py::object(py::none()),
        py::arg("workspace_used_bytes") = r.workspace_used_bytes);
}

// The points as the library reads them, with the array that owns them kept alive.
struct Points {
    py::array array;
    stratmesh::Cloud cloud;
};

// Reads an (n, 3) float32 or float64 array in place when each point's x, y, z are adjacent
// and rows do not overlap (any row stride, so views of wider records need no copy);
// otherwise copies it into a packed array, or refuses when copy is false.
Points as_points(py::handle object, bool copy) {
    py::array a = py::array::ensure(object);
    if (!a) raise_wrong_type("points must be an (n, 3) array of float32 or float64");
    py::dtype dtype = a.dtype();
    if (dtype.kind() != 'f' || (dtype.itemsize() != 4 && dtype.itemsize() != 8))
        raise_wrong_type("points must be an (n, 3) array of float32 or float64, not of " +
                         std::string(py::str(dtype)));
    if (a.ndim() != 2 || a.shape(1) != 3)
        raise_argument("points must be an (n, 3) array of float32 or float64, not of shape " +
                       std::string(py::str(py::tuple(a.attr("shape")))));
    const py::ssize_t item = dtype.itemsize();
    const bool native = dtype.attr("isnative").cast<bool>();
    const bool in_place = native && a.strides(1) == item &&
                          (a.shape(0) <= 1 || a.strides(0) >= 3 * item);
    if (!in_place) {
        if (!copy)
            raise_argument("points: each point's x, y, z are not adjacent in memory (or rows "
                           "overlap, or the byte order is not native) and copy=False forbids a "
                           "copy");
        a = py::module_::import("numpy").attr("ascontiguousarray")(
            a, py::arg("dtype") = dtype.attr("newbyteorder")("="));
    }
    Points p;
    p.cloud.xyz = a.data();
    p.cloud.count = static_cast<size_t>(a.shape(0));
    // A single point's row stride may be anything; 0 tells the library "packed".
    p.cloud.stride_bytes = a.shape(0) <= 1 ? 0 : static_cast<size_t>(a.strides(0));
    p.cloud.scalar = item == 4 ? stratmesh::Scalar::float32 : stratmesh::Scalar::float64;
    p.array = std::move(a);
    return p;
}

// The Options with what they point at (the cuts) kept alive. Built from the dict that
// stratmesh's Python layer makes of the keyword arguments.
struct OptionSet {
    stratmesh::Options options = {};
    py::array_t<double, py::array::c_style | py::array::forcecast> cuts;
    unsigned threads = 1;
};

void read_options(const py::dict& d, OptionSet& set) {
    stratmesh::Options& o = set.options;
    o.axis = static_cast<stratmesh::Axis>(d["axis"].cast<uint32_t>());
    py::tuple direction = d["direction"].cast<py::tuple>();
    py::tuple origin = d["origin"].cast<py::tuple>();
    for (size_t i = 0; i < 3; ++i) {
        o.direction[i] = direction[i].cast<double>();
        o.origin[i] = origin[i].cast<double>();
    }
    if (!d["cuts"].is_none()) {
        set.cuts = d["cuts"].cast<py::array_t<double, py::array::c_style | py::array::forcecast>>();
        o.cuts = set.cuts.data();
        o.cut_count = static_cast<size_t>(set.cuts.size());
    }
    o.layer_count = d["layer_count"].cast<uint32_t>();
    o.layer_height = d["layer_height"].cast<double>();
    o.flags = d["flags"].cast<uint32_t>();
    o.parts = static_cast<stratmesh::Parts>(d["parts"].cast<uint32_t>());
    set.threads = d["threads"].cast<unsigned>();
}

// Runs a batch of the library's jobs on up to *user threads, the caller's included. Threads
// are started per batch: a batch is a run of layers, long beside a thread's start.
void run_on_threads(void* user, uint32_t count, stratmesh::JobFunction job, void* context) {
    const unsigned threads = *static_cast<const unsigned*>(user);
    std::atomic<uint32_t> next(0);
    auto work = [&] {
        for (uint32_t i = next.fetch_add(1); i < count; i = next.fetch_add(1)) job(context, i);
    };
    std::vector<std::thread> helpers;
    try {
        const uint32_t extra = std::min<uint32_t>(threads, count) - (count > 0 ? 1 : 0);
        helpers.reserve(extra);
        for (uint32_t t = 0; t < extra; ++t) helpers.emplace_back(work);
    } catch (const std::exception&) {
        // Fewer threads only cost time: whatever the helpers do not take, this thread runs.
    }
    work();
    for (std::thread& t : helpers) t.join();
}

// Calls a Python progress callback from the library; an exception it raises is kept and
// raised once the library returns (the call itself cannot be stopped).
struct Progress {
    py::object callback;
    std::unique_ptr<py::error_already_set> error;
};

void progress_hook(void* user, stratmesh::Phase phase, double fraction) {
    Progress* p = static_cast<Progress*>(user);
    py::gil_scoped_acquire gil;
    if (p->error) return;
    try {
        p->callback(phase_name(phase), fraction);
    } catch (py::error_already_set& e) {
        p->error.reset(new py::error_already_set(std::move(e)));
    }
}

// A malloc'd triangle array handed to numpy without a copy; shrunk in place by realloc.
py::array_t<uint32_t> triangle_array(uint32_t* data, size_t count) {
    void* shrunk = std::realloc(data, std::max<size_t>(count, 1) * 3 * sizeof(uint32_t));
    if (shrunk) data = static_cast<uint32_t*>(shrunk);
    py::capsule owner(data, [](void* p) { std::free(p); });
    return py::array_t<uint32_t>({static_cast<py::ssize_t>(count), py::ssize_t(3)}, data, owner);
}

uint32_t* allocate_triangles(size_t capacity) {
    void* data = std::malloc(std::max<size_t>(capacity, 1) * 3 * sizeof(uint32_t));
    if (!data) throw std::bad_alloc();
    return static_cast<uint32_t*>(data);
}

// A *_workspace_size() of 0 means no workspace can serve that many points.
void check_workspace_size(size_t bytes, size_t points) {
    if (bytes == 0 && points > 0)
        raise_error(stratmesh::Status::too_many_points,
                    ("points holds " + std::to_string(points) +
                     ", more than one workspace serves (the library addresses 2^32 - 2)")
                        .c_str(),
                    py::none());
}

std::unique_ptr<unsigned char[]> allocate_workspace(size_t bytes, size_t points) {
    check_workspace_size(bytes, points);
    // Not value-initialised: the library needs no zeroed memory, and zeroing costs a pass.
    return std::unique_ptr<unsigned char[]>(new unsigned char[std::max<size_t>(bytes, 1)]);
}

// A workspace kept between reconstruct() calls, so that its pages, touched once, cost
// nothing the next time. Grows to the largest call's need; serves one call at a time.
class Workspace {
public:
    size_t size() const { return size_; }

    // The workspace for a call of `bytes`, held until the Lease ends.
    class Lease {
    public:
        Lease(Workspace& w, size_t bytes, size_t points) : w_(w) {
            if (w.busy_) raise_argument("workspace is in use by another call");
            check_workspace_size(bytes, points);
            if (bytes > w.size_) {
                w.data_ = allocate_workspace(bytes, points);
                w.size_ = bytes;
            }
            w.busy_ = true;
        }
        ~Lease() { w_.busy_ = false; }
        unsigned char* get() const { return w_.data_.get(); }

    private:
        Workspace& w_;
    };

private:
    std::unique_ptr<unsigned char[]> data_;
    size_t size_ = 0;
    bool busy_ = false;
};

py::tuple reconstruct(py::handle object, const py::dict& option_dict, py::object progress,
                      bool copy, py::object kept) {
    Points points = as_points(object, copy);
    OptionSet set;
    read_options(option_dict, set);
    stratmesh::Options& options = set.options;
    if (set.threads > 1) {
        options.run_jobs = run_on_threads;
        options.jobs_user = &set.threads;
    }
    Progress hook{progress, nullptr};
    if (!progress.is_none()) {
        options.progress = progress_hook;
        options.progress_user = &hook;
    }
    const size_t n = points.cloud.count;
    const size_t bytes = stratmesh::reconstruct_workspace_size(n, options);
    check_workspace_size(bytes, n);  // before the arrays sized by n are allocated
    const size_t capacity = stratmesh::reconstruct_max_triangles(n, options);
    // Every layer holds 16 distinct points or more, so this many entries hold every layer;
    // left uninitialised, the pages the library does not fill are never touched.
    const size_t layer_capacity = n / 16 + 1;
    std::unique_ptr<stratmesh::LayerInfo[]> layers(new stratmesh::LayerInfo[layer_capacity]);
    std::unique_ptr<uint32_t, void (*)(void*)> triangles(allocate_triangles(capacity), std::free);
    stratmesh::Report report = {};
    report.layers.info = layers.get();
    report.layers.info_capacity = layer_capacity;
    size_t count = 0;
    stratmesh::Status status;
    if (kept.is_none()) {
        std::unique_ptr<unsigned char[]> workspace = allocate_workspace(bytes, n);
        py::gil_scoped_release release;
        status = stratmesh::reconstruct(points.cloud, options, workspace.get(), bytes,
                                        triangles.get(), capacity, &count, &report);
    } else {
        Workspace::Lease workspace(kept.cast<Workspace&>(), bytes, n);
        py::gil_scoped_release release;
        status = stratmesh::reconstruct(points.cloud, options, workspace.get(), bytes,
                                        triangles.get(), capacity, &count, &report);
    }
    if (hook.error) {
        hook.error->restore();
        throw py::error_already_set();
    }
    py::object report_py = report_object(report, status);
    if (status != stratmesh::Status::ok) raise_error(status, report.detail, report_py);
    return py::make_tuple(triangle_array(triangles.release(), count), report_py);
}

py::tuple cap_ends(py::handle object, py::handle triangles_in, const py::dict& option_dict,
                   bool copy) {
    Points points = as_points(object, copy);
    OptionSet set;
    read_options(option_dict, set);
    using Indices = py::array_t<uint32_t, py::array::c_style | py::array::forcecast>;
    Indices given = Indices::ensure(triangles_in);
    if (!given || given.ndim() != 2 || given.shape(1) != 3)
        raise_argument("triangles must be an (m, 3) array of indices");
    const size_t n = points.cloud.count;
    const size_t have = static_cast<size_t>(given.shape(0));
    const size_t capacity = std::max(have, stratmesh::reconstruct_max_triangles(n, set.options));
    const size_t bytes = stratmesh::cap_ends_workspace_size(n, have);
    std::unique_ptr<unsigned char[]> workspace = allocate_workspace(bytes, n);
    std::unique_ptr<uint32_t, void (*)(void*)> triangles(allocate_triangles(capacity), std::free);
    std::copy(given.data(), given.data() + 3 * have, triangles.get());
    stratmesh::Report report = {};
    size_t count = have;
    stratmesh::Status status;
    {
        py::gil_scoped_release release;
        status = stratmesh::cap_ends(points.cloud, set.options, workspace.get(), bytes,
                                     triangles.get(), capacity, &count, &report);
    }
    py::object report_py = report_object(report, status);
    if (status != stratmesh::Status::ok) raise_error(status, report.detail, report_py);
    return py::make_tuple(triangle_array(triangles.release(), count), report_py);
}

// A stream in a workspace this object owns. Triangles the library emits during a push or
// the close are gathered in a vector, which numpy then owns without a copy.
class Stream {
public:
    Stream(const py::dict& option_dict, size_t max_points, size_t layer_info)
        // Not value-initialised: the report shows only the entries the library fills, so
        // a large layer_info costs address space, not pages.
        : layers_(new stratmesh::LayerInfo[layer_info]) {
        OptionSet set;
        read_options(option_dict, set);
        const size_t bytes = stratmesh::stream_workspace_size(max_points, set.options);
        workspace_ = allocate_workspace(bytes, max_points);
        report_.layers.info = layers_.get();
        report_.layers.info_capacity = layer_info;
        stratmesh::Status status = stratmesh::stream_open(set.options, workspace_.get(), bytes,
                                                          emit, this, &report_, &stream_);
        if (status != stratmesh::Status::ok)
            raise_error(status, report_.detail, report_object(report_, status));
    }

    py::array_t<uint32_t> push(py::handle object, double top, bool copy) {
        Points points = as_points(object, copy);
        return run([&] { return stratmesh::stream_push(stream_, points.cloud, top); });
    }

    py::array_t<uint32_t> close() {
        py::array_t<uint32_t> triangles = run([&] { return stratmesh::stream_close(stream_); });
        closed_ = true;
        return triangles;
    }

    py::object report() const { return report_object(report_, last_); }
    bool closed() const { return closed_; }

private:
    static void emit(void* user, const uint32_t* triangles, size_t count) {
        std::vector<uint32_t>& out = *static_cast<Stream*>(user)->out_;
        out.insert(out.end(), triangles, triangles + 3 * count);
    }

    template <typename Call>
    py::array_t<uint32_t> run(Call call) {
        if (closed_) raise_argument("the stream is closed");
        // The stream belongs to one thread at a time; the GIL is released while it runs.
        if (busy_) raise_argument("the stream is in use by another thread");
        busy_ = true;
        out_.reset(new std::vector<uint32_t>());
        {
            py::gil_scoped_release release;
            last_ = call();
        }
        busy_ = false;
        if (last_ != stratmesh::Status::ok)
            raise_error(last_, report_.detail, report_object(report_, last_));
        std::vector<uint32_t>* out = out_.release();
        py::capsule owner(out, [](void* p) { delete static_cast<std::vector<uint32_t>*>(p); });
        return py::array_t<uint32_t>({static_cast<py::ssize_t>(out->size() / 3), py::ssize_t(3)},
                                     out->data(), owner);
    }

    std::unique_ptr<stratmesh::LayerInfo[]> layers_;
    std::unique_ptr<unsigned char[]> workspace_;
    stratmesh::Report report_ = {};
    stratmesh::Stream* stream_ = nullptr;
    std::unique_ptr<std::vector<uint32_t>> out_;
    stratmesh::Status last_ = stratmesh::Status::ok;
    bool busy_ = false;
    bool closed_ = false;
};

}  // namespace

PYBIND11_MODULE(_core, m) {
    m.doc() = "stratmesh's C++ core; use the stratmesh package, which wraps it.";
    m.attr("__version__") = STRATMESH_VERSION_STRING;
    py::dict flags;
    for (const FlagName& f : kFlags) flags[f.name] = f.bit;
    m.attr("FLAGS") = flags;
    py::dict parts;
    for (const PartsName& p : kParts) parts[p.name] = static_cast<uint32_t>(p.parts);
    m.attr("PARTS") = parts;
    py::dict statuses;
#define STRATMESH_PY_ENTRY(name, message) statuses[#name] = message;
    STRATMESH_STATUS_LIST(STRATMESH_PY_ENTRY)
#undef STRATMESH_PY_ENTRY
    m.attr("STATUSES") = statuses;
    m.attr("POOR_MISFIT_FRACTION") = stratmesh::kPoorMisfitFraction;
    m.def("reconstruct", &reconstruct, py::arg("points"), py::arg("options"),
          py::arg("progress"), py::arg("copy"), py::arg("workspace"));
    py::class_<Workspace>(m, "Workspace")
        .def(py::init<>())
        .def_property_readonly("size", &Workspace::size);
    m.def("cap_ends", &cap_ends, py::arg("points"), py::arg("triangles"), py::arg("options"),
          py::arg("copy"));
    m.def("stream_workspace_size", [](size_t max_points, const py::dict& option_dict) {
        OptionSet set;
        read_options(option_dict, set);
        return stratmesh::stream_workspace_size(max_points, set.options);
    });
    py::class_<Stream>(m, "Stream")
        .def(py::init<const py::dict&, size_t, size_t>(), py::arg("options"),
             py::arg("max_points"), py::arg("layer_info"))
        .def("push", &Stream::push, py::arg("points"), py::arg("top"), py::arg("copy"))
        .def("close", &Stream::close)
        .def_property_readonly("report", &Stream::report)
        .def_property_readonly("closed", &Stream::closed);
}
