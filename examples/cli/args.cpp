#include "args.h"

#include "mesh_io.h"
#include "text_scan.h"

#include <cmath>
#include <iterator>
#include <string_view>
#include <thread>

namespace stratmesh_cli {

namespace {

const char kUsage[] =
    "Usage: stratmesh INPUT -o OUTPUT [options]\n"
    "       (INPUT - reads standard input; -o - --format F writes standard output)\n"
    "\n"
    "Reconstructs a triangle mesh through the points of a roughly columnar cloud (a head,\n"
    "a limb, a bone, a stem): the cloud is sliced into layers along an axis and each\n"
    "layer is unrolled from a cylinder and triangulated.\n"
    "\n"
    "Input, recognised by its content (the extension is only a hint):\n"
    "  PLY      ascii, binary_little_endian or binary_big_endian; x, y, z of the vertex\n"
    "           element (float, double or an integer type); its other scalar properties\n"
    "           go to the output (see --no-attributes); everything else is skipped\n"
    "  XYZ      .xyz .pts .txt .csv: 3 or more numeric columns separated by spaces and\n"
    "           tabs, commas or semicolons, the same on every line; a decimal point, or a\n"
    "           decimal comma with semicolons or blanks; '#' and '//' comments; a PTS\n"
    "           count line is skipped (docs/formats.md says exactly what is read)\n"
    "  OFF, OBJ their vertices; faces are ignored (with a warning that counts them)\n"
    "  -        standard input, its format recognised the same way\n"
    "\n"
    "Output, by the extension of OUTPUT or --format:\n"
    "  .ply binary little-endian (text with --ascii)   .obj  text\n"
    "  .stl binary (text with --ascii)                 .off  text\n"
    "  The output vertices are the input points as read, all of them and in input order,\n"
    "  even the points no triangle uses (duplicates, rejected, unused): vertex i of OUTPUT\n"
    "  is point i of INPUT, so the triangles index the input unchanged. STL has no shared\n"
    "  vertices and only lists triangles.\n"
    "\n"
    "Options:\n"
    "  -o, --output FILE     the mesh to write (required); - for standard output\n"
    "  --format ply|obj|off|stl  the output's format, whatever its extension (required\n"
    "                        with -o -)\n"
    "  --axis x|y|z|X,Y,Z    the axis the layers are stacked along (default: automatic,\n"
    "                        the cloud's principal direction; x or X alike); a direction\n"
    "                        of any finite non-zero length\n"
    "  --cuts H1,H2,...      cut the layers at these positions along the axis, measured\n"
    "                        as dot(point, unit axis): with --axis z, 68 is the plane z = 68;\n"
    "                        cuts outside the cloud are ignored, with a warning\n"
    "  --layers N            N layers of equal height\n"
    "  --layer-height H      layers about H high\n"
    "                        (at most one of --cuts, --layers, --layer-height; without\n"
    "                        them the layers are chosen automatically)\n"
    "  --report FILE.json    write counts, timings, memory and per-layer details as JSON\n"
    "                        (- for standard output, as for --preview)\n"
    "  --preview FILE.svg    draw the mesh from the front and the side (orthographic,\n"
    "                        shaded, the layers in alternating tints, the boundary edges\n"
    "                        in red): a polygon per triangle and view, about 200 bytes\n"
    "                        a triangle (not with --stream)\n"
    "  --ascii               text PLY or STL\n"
    "  --no-attributes       write only the points' coordinates: without it, the other\n"
    "                        vertex properties of a PLY input (normals, colours,\n"
    "                        intensity, any scalar; not lists) go with each vertex,\n"
    "                        unchanged into a PLY output (same names, types and values),\n"
    "                        the normals (vn) and colours (v x y z r g b, 0 to 1) into\n"
    "                        OBJ; OFF, STL and --stream carry none\n"
    "  --skip-invalid        skip points with NaN or infinite coordinates (they stay in\n"
    "                        the output, unused) instead of refusing the input\n"
    "  --drop-outliers       leave out points far from the rest of the cloud (stray\n"
    "                        returns, specks of fewer than 8 points); they stay in the\n"
    "                        output, unused, counted as rejected (outliers)\n"
    "  --surface-flips       after each layer is triangulated on its unrolled annulus (the\n"
    "                        paper's method), flip its edges on the surface in 3D, by the\n"
    "                        empty-circle rule and toward where the surface curves least\n"
    "                        (stratmesh's surface_flips): closer to the true surface where\n"
    "                        the unrolling squeezes it, fewer slivers, for 1.2 to 6\n"
    "                        times the time\n"
    "  --ends-are-cuts       take no end of the cloud for a closed one (a dome, a base,\n"
    "                        otherwise meshed across from a pole): both are unrolled on\n"
    "                        the cylinder like the rest; for a cloud cut out of a larger\n"
    "                        object (stratmesh's ends_are_cuts)\n"
    "  --parts automatic|one-tube|apart  where the cloud parts into branches (see\n"
    "                        Branches below): automatic (the default) looks and joins\n"
    "                        the parts where that is whole and smaller than one tube;\n"
    "                        one-tube does not look: one tube through every point; apart\n"
    "                        keeps the parts even where a side cannot be joined (left\n"
    "                        apart, as the summary says) or points past a cut are in no\n"
    "                        branch (left unused)\n"
    "  --branches            only find and report where the cloud parts (summary and\n"
    "                        report), and mesh one tube\n"
    "  --cap                 close the tube's ends with caps over its boundary loops: a\n"
    "                        closed, watertight surface (a loop that cannot be capped\n"
    "                        stays open; the summary and the report count it). Parts\n"
    "                        meshed apart are capped once joined (stratmesh's cap_ends)\n"
    "  --threads N           triangulate the layers on N threads (default: the machine's\n"
    "                        hardware threads); the output is the same bytes for any N\n"
    "  --origin X,Y,Z        the reference point of the unrolling frame (default: the\n"
    "                        cloud's centroid; with --stream, the first valid point);\n"
    "                        within 2^32 times the cloud's size of the cloud\n"
    "  --stream              read and reconstruct layer by layer in bounded memory; needs\n"
    "                        --axis x|y|z|X,Y,Z and --cuts or --layer-height, points\n"
    "                        sorted along the axis, input PLY, XYZ or OBJ, output PLY, OBJ\n"
    "                        or OFF (not STL). The same triangles as the run without\n"
    "                        --stream given --cuts at the layer tops reached (the report's\n"
    "                        stream.batch_cuts) and --origin at that first point. With\n"
    "                        --cap it keeps every point and triangle until the end (about\n"
    "                        140 bytes a point more) and caps them as the run without\n"
    "                        --stream would\n"
    "  --stream-points N     the most points the stream may hold at once (default\n"
    "                        3000000, about 190 bytes each; never more than the input\n"
    "                        file can hold); about three layers' worth. Where a layer\n"
    "                        does not fit, or the memory does not hold them, the tool\n"
    "                        says how many to give instead\n"
    "  -q, --quiet           no progress and no summary on stderr (warnings and errors\n"
    "                        still are)\n"
    "  --verbose             the summary also gives the branches and parts, the threads,\n"
    "                        the times, the memory and the stream\n"
    "  --strict              a poor verdict makes the exit status 5 (the mesh is still\n"
    "                        written)\n"
    "  --version             print the version and exit\n"
    "  -h, --help            print this help and exit\n"
    "\n"
    "Bends:\n"
    "  An object that bends without branching (an elbow, a U bend, a coil, a bowed bone)\n"
    "  is no column along any axis. Unless --axis, --cuts, --layers, --layer-height,\n"
    "  --origin or --parts one-tube is given, the tool first looks for its skeleton (rings\n"
    "  of equal distance along the surface from one end, one at every distance, their\n"
    "  centres a curve that strays from a straight line) and slices the layers across it;\n"
    "  the verdict then says \"along its bent skeleton (N nodes)\", and the report's layer\n"
    "  heights are arc lengths along it. --stream stacks its layers along its axis.\n"
    "\n"
    "Branches:\n"
    "  Where the cloud parts into branches along the axis (horns on a skull, the prongs\n"
    "  of a fork), one tube would wrap them and the gaps between them. By default the tool\n"
    "  looks (stratmesh's find_parting: the lowest cut above which and the highest below\n"
    "  which the points make separate branches, squared to the trunk's own axis where it\n"
    "  leans up to 30 degrees from the axis; the summary gives the cuts' axis), meshes the\n"
    "  trunk and each branch around their own automatic axes (the trunk along the cuts'\n"
    "  axis when --cuts, --layers or --layer-height lay it out) and joins them\n"
    "  (stratmesh's join_branches: to the trunk's loop at the cut where it goes around\n"
    "  the branches, else each branch grafted onto a hole cut in the trunk's end under\n"
    "  it). It keeps that only if every part was meshed, every side joined,\n"
    "  every point belongs to a part and the surface is smaller than one tube's; else it\n"
    "  meshes the cloud as one tube, as the summary says. Looking costs about 100 bytes a\n"
    "  point; where nothing parts the mesh is the one tube's. With --stream the tool does\n"
    "  not look.\n"
    "\n"
    "Summary, on stderr: the input and output, the points, the layers (asked and used,\n"
    "and why layers were merged), the triangles and the ends (closed only where no\n"
    "boundary loop is left; a small loop around a pole is named), the warnings count, and\n"
    "the verdict: good, or poor with how much of the surface does not follow the cloud\n"
    "(folds across it or spans gaps), where, the crossing triangles, and the one action\n"
    "that helps, with the axis and layers used. --stream does not measure the fit. The\n"
    "warnings follow, each on a line 'stratmesh: warning: ...': branches left apart,\n"
    "points left out, caps left open, input faces ignored, cuts outside the cloud (and a\n"
    "poor verdict, under --quiet). --verbose adds the folds the library settled and the\n"
    "branches one tube wraps.\n"
    "\n"
    "Files: no output may be the input or another output, by any name (a symlink, a hard\n"
    "link, standard input or output redirected from or to it), and at most one of -o,\n"
    "--report and --preview may be - (standard output); that is refused before anything is\n"
    "read. The outputs are written to temporaries beside them and renamed into place\n"
    "together once every one is complete: any failure leaves every file as it was. Standard\n"
    "output, devices and pipes are written directly, before any file is renamed; what one\n"
    "received stays if a later output fails.\n"
    "\n"
    "Exit status: 0 success; 1 the reconstruction refused the input; 2 usage error;\n"
    "3 file error (cannot open, read, parse or write; standard output closed early); 4 with\n"
    "--stream, a point lies below the one before it along the axis (sort the input along\n"
    "the axis first); 5 with --strict, the mesh was written but judged poor.\n";

bool parse_finite(std::string_view text, double& value) {
    return parse_number(text, value) && std::isfinite(value);
}

// Comma-separated finite numbers, none empty.
bool parse_number_list(std::string_view text, std::vector<double>& values) {
    values.clear();
    for (;;) {
        size_t comma = text.find(',');
        double value = 0;
        if (!parse_finite(text.substr(0, comma), value)) return false;
        values.push_back(value);
        if (comma == std::string_view::npos) return true;
        text.remove_prefix(comma + 1);
    }
}

bool parse_axis(std::string_view text, CommandLine& line, std::string& error) {
    const struct {
        const char* name;
        stratmesh::Axis axis;
    } names[] = {{"x", stratmesh::Axis::x},
                 {"y", stratmesh::Axis::y},
                 {"z", stratmesh::Axis::z},
                 {"auto", stratmesh::Axis::automatic},
                 {"automatic", stratmesh::Axis::automatic}};
    std::string lower(text);
    for (char& c : lower)
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    for (const auto& n : names) {
        if (lower == n.name) {
            line.axis = n.axis;
            return true;
        }
    }
    std::vector<double> v;
    if (!parse_number_list(text, v) || v.size() != 3) {
        error = "--axis: expected x, y, z or a direction X,Y,Z, not '" + std::string(text) + "'";
        return false;
    }
    // Passed as given: the library takes any finite non-zero length (1e308,0,0 and 1e-320,0,0).
    if (v[0] == 0 && v[1] == 0 && v[2] == 0) {
        error = "--axis: the direction must not be zero";
        return false;
    }
    line.axis = stratmesh::Axis::direction;
    for (size_t k = 0; k < 3; ++k) line.direction[k] = v[k];
    return true;
}

bool parse_layers(std::string_view text, CommandLine& line, std::string& error) {
    uint64_t count = 0;
    if (parse_count(text, count) != CountParse::ok || count < 1 || count > UINT32_MAX) {
        error = "--layers: expected a whole number from 1 to 4294967295, not '" +
                std::string(text) + "'";
        return false;
    }
    line.layer_count = static_cast<uint32_t>(count);
    return true;
}

bool parse_layer_height(std::string_view text, CommandLine& line, std::string& error) {
    if (parse_finite(text, line.layer_height) && line.layer_height > 0) return true;
    error = "--layer-height: expected a positive number, not '" + std::string(text) + "'";
    return false;
}

bool parse_threads(std::string_view text, CommandLine& line, std::string& error) {
    uint64_t count = 0;
    if (parse_count(text, count) != CountParse::ok || count < 1 || count > 1024) {
        error = "--threads: expected a whole number from 1 to 1024, not '" + std::string(text) +
                "'";
        return false;
    }
    line.threads = static_cast<uint32_t>(count);
    return true;
}

bool parse_stream_points(std::string_view text, CommandLine& line, std::string& error) {
    if (parse_count(text, line.stream_points) == CountParse::ok && line.stream_points >= 16)
        return true;
    error = "--stream-points: expected a whole number of at least 16, not '" + std::string(text) +
            "'";
    return false;
}

bool parse_origin(std::string_view text, CommandLine& line, std::string& error) {
    std::vector<double> v;
    if (!parse_number_list(text, v) || v.size() != 3) {
        error = "--origin: expected a point X,Y,Z, not '" + std::string(text) + "'";
        return false;
    }
    line.origin_given = true;
    for (size_t k = 0; k < 3; ++k) line.origin[k] = v[k];
    return true;
}

bool parse_format(std::string_view text, CommandLine& line, std::string& error) {
    line.output_format = mesh_format_from_extension("." + std::string(text));
    if (line.output_format != MeshFormat::unknown) return true;
    error = "--format: expected ply, obj, off or stl, not '" + std::string(text) + "'";
    return false;
}

bool parse_parts(std::string_view text, CommandLine& line, std::string& error) {
    const stratmesh::Parts choices[] = {stratmesh::Parts::automatic, stratmesh::Parts::one_tube,
                                        stratmesh::Parts::apart};
    for (stratmesh::Parts parts : choices)
        if (text == parts_name(parts)) {
            line.parts = parts;
            line.parts_given = true;
            return true;
        }
    error = "--parts: expected automatic, one-tube or apart, not '" + std::string(text) + "'";
    return false;
}

bool parse_cuts(std::string_view text, CommandLine& line, std::string& error) {
    if (parse_number_list(text, line.cuts)) return true;
    error = "--cuts: expected numbers separated by commas, not '" + std::string(text) + "'";
    return false;
}

// Applies an option that takes a value; `name` is its canonical long form.
bool apply_valued(std::string_view name, std::string_view value, CommandLine& line,
                  std::string& error) {
    if (name == "--output") line.output = std::string(value);
    if (name == "--report") line.report = std::string(value);
    if (name == "--preview") line.preview = std::string(value);
    if (name == "--axis") return parse_axis(value, line, error);
    if (name == "--cuts") return parse_cuts(value, line, error);
    if (name == "--layers") return parse_layers(value, line, error);
    if (name == "--layer-height") return parse_layer_height(value, line, error);
    if (name == "--threads") return parse_threads(value, line, error);
    if (name == "--stream-points") return parse_stream_points(value, line, error);
    if (name == "--origin") return parse_origin(value, line, error);
    if (name == "--format") return parse_format(value, line, error);
    if (name == "--parts") return parse_parts(value, line, error);
    if (value.empty()) error = std::string(name) + ": the file name is empty";
    return error.empty();
}

bool apply_flag(std::string_view name, CommandLine& line) {
    if (name == "--ascii") line.ascii = true;
    if (name == "--no-attributes") line.no_attributes = true;
    if (name == "--skip-invalid") line.skip_invalid = true;
    if (name == "--cap") line.cap = true;
    if (name == "--drop-outliers") line.drop_outliers = true;
    if (name == "--surface-flips") line.surface_flips = true;
    if (name == "--ends-are-cuts") line.ends_are_cuts = true;
    if (name == "--branches") line.find_branches = true;
    if (name == "--quiet") line.quiet = true;
    if (name == "--verbose") line.verbose = true;
    if (name == "--strict") line.strict = true;
    if (name == "--stream") line.stream = true;
    return true;
}

const char* const kValuedOptions[] = {"--output",  "--report",        "--axis",
                                      "--cuts",    "--layers",        "--layer-height",
                                      "--threads", "--stream-points", "--origin",
                                      "--format",  "--preview",       "--parts"};
const char* const kFlags[] = {"--ascii", "--skip-invalid", "--cap",     "--quiet",
                              "--help",  "--version",      "--stream", "--drop-outliers",
                              "--surface-flips", "--ends-are-cuts", "--branches",
                              "--verbose", "--strict", "--no-attributes"};

// What --stream cannot do, or an empty string.
std::string stream_conflict(const CommandLine& line) {
    if (line.axis == stratmesh::Axis::automatic)
        return "--stream needs --axis x, y, z or X,Y,Z: the automatic axis is the principal "
               "direction of the whole cloud, unknown until every point is read";
    if (line.cuts.empty() && line.layer_height <= 0)
        return "--stream needs --cuts or --layer-height: the layers are formed as the points "
               "arrive (--layers and automatic layers need the whole cloud's height)";
    if (line.drop_outliers)
        return "--stream cannot --drop-outliers: an outlier is told from the whole cloud's "
               "spacing, which the stream never holds";
    if (line.find_branches || line.parts == stratmesh::Parts::apart)
        return "--stream cannot find --branches (nor --parts apart): where a cloud parts "
               "is told from all of its points, which the stream never holds";
    if (!line.preview.empty())
        return "--stream cannot --preview: it writes the triangles as they come and keeps "
               "none to draw";
    if (line.output_format == MeshFormat::stl)
        return "--stream cannot write STL (its triangles repeat their corners' coordinates, "
               "which the stream no longer holds): write PLY, OBJ or OFF";
    return "";
}

// How many of -o, --report and --preview go to standard output.
int standard_outputs(const CommandLine& line) {
    int count = 0;
    for (const std::string* path : {&line.output, &line.report, &line.preview})
        if (*path == kStandardStream) ++count;
    return count;
}

// The machine's hardware threads, at least 1.
uint32_t default_threads() {
    unsigned count = std::thread::hardware_concurrency();
    return count > 0 ? count : 1;
}

std::string_view canonical_name(std::string_view name) {
    if (name == "-o") return "--output";
    if (name == "-q") return "--quiet";
    if (name == "-h") return "--help";
    return name;
}

bool is_one_of(std::string_view name, const char* const* list, size_t count) {
    for (size_t i = 0; i < count; ++i)
        if (name == list[i]) return true;
    return false;
}

// Walks argv, remembering the first error but still noticing --help and --version.
class Parser {
public:
    Parser(int argc, const char* const* argv, CommandLine& line)
        : argc_(argc), argv_(argv), line_(line) {}

    CommandAction run(std::string& error) {
        line_.threads = default_threads();
        for (index_ = 1; index_ < argc_; ++index_) take(argv_[index_]);
        if (help_) return CommandAction::help;
        if (version_) return CommandAction::version;
        if (error_.empty()) check_complete();
        error = error_;
        return error_.empty() ? CommandAction::run : CommandAction::usage_error;
    }

private:
    void fail(const std::string& message) {
        if (error_.empty()) error_ = message;
    }

    void take(std::string_view arg) {
        if (!options_ended_ && arg == "--") {
            options_ended_ = true;
        } else if (options_ended_ || arg.size() < 2 || arg[0] != '-') {
            take_input(arg);
        } else {
            take_option(arg);
        }
    }

    void take_input(std::string_view arg) {
        if (!line_.input.empty()) {
            if (extra_input_.empty()) extra_input_ = std::string(arg);
            return;
        }
        line_.input = std::string(arg);
    }

    void take_option(std::string_view arg) {
        size_t equals = arg.substr(0, 2) == "--" ? arg.find('=') : std::string_view::npos;
        std::string_view name = canonical_name(arg.substr(0, equals));
        bool inline_value = equals != std::string_view::npos;
        std::string_view value = inline_value ? arg.substr(equals + 1) : std::string_view();
        if (is_one_of(name, kFlags, std::size(kFlags))) {
            take_flag(name, inline_value);
        } else if (is_one_of(name, kValuedOptions, std::size(kValuedOptions))) {
            take_valued(name, inline_value, value);
        } else {
            fail("unknown option '" + std::string(arg) + "'");
        }
    }

    void take_flag(std::string_view name, bool inline_value) {
        if (inline_value) fail("option " + std::string(name) + " takes no value");
        if (name == "--help") help_ = true;
        if (name == "--version") version_ = true;
        apply_flag(name, line_);
    }

    void take_valued(std::string_view name, bool inline_value, std::string_view value) {
        if (!inline_value) {
            if (index_ + 1 >= argc_) return fail("option " + std::string(name) + " needs a value");
            value = argv_[++index_];
        }
        std::string key(name);
        if (seen_.find(" " + key + " ") != std::string::npos)
            return fail("option " + key + " is given more than once");
        seen_ += " " + key + " ";
        std::string message;
        if (!apply_valued(name, value, line_, message)) fail(message);
    }

    void check_complete() {
        int layer_choices = (line_.cuts.empty() ? 0 : 1) + (line_.layer_count ? 1 : 0) +
                            (line_.layer_height > 0 ? 1 : 0);
        if (line_.input.empty()) return fail("no input file");
        if (!extra_input_.empty()) {
            // Two file names and no -o: most likely the output's -o was left out.
            const std::string hint = line_.output.empty() ? "; did you mean: stratmesh " +
                                                                line_.input + " -o " +
                                                                extra_input_ + "?"
                                                          : "";
            return fail("more than one input file ('" + line_.input + "' and '" +
                        extra_input_ + "')" + hint);
        }
        if (line_.output.empty()) return fail("no output file (use -o OUTPUT)");
        if (standard_outputs(line_) > 1)
            return fail("at most one of -o, --report and --preview may be - (standard "
                        "output): one stream cannot hold two files; give the others paths");
        if (line_.output_format == MeshFormat::unknown && line_.output == "-")
            return fail("-o - writes to standard output: give its format with --format "
                        "ply|obj|off|stl");
        if (line_.output_format == MeshFormat::unknown)
            line_.output_format = mesh_format_from_extension(line_.output);
        if (line_.output_format == MeshFormat::unknown)
            return fail("cannot tell the mesh format of '" + line_.output +
                        "' from its extension (use .ply, .obj, .off or .stl, or --format)");
        if (line_.quiet && line_.verbose) return fail("give at most one of --quiet and --verbose");
        if (layer_choices > 1)
            return fail("give at most one of --cuts, --layers and --layer-height");
        if (line_.find_branches && line_.parts_given)
            return fail("give at most one of --branches and --parts: --branches meshes one "
                        "tube");
        if (line_.stream) fail(stream_conflict(line_));
    }

    int argc_;
    const char* const* argv_;
    CommandLine& line_;
    int index_ = 1;
    bool options_ended_ = false;
    bool help_ = false;
    bool version_ = false;
    std::string seen_; // " --name " for each valued option seen
    std::string extra_input_; // the first file name after the input, if any
    std::string error_;
};

} // namespace

CommandAction parse_command_line(int argc, const char* const* argv, CommandLine& line,
                                 std::string& error) {
    return Parser(argc, argv, line).run(error);
}

std::vector<NamedFile> named_files(const CommandLine& line) {
    std::vector<NamedFile> files;
    const NamedFile all[] = {{"the input", line.input, true},
                             {"-o", line.output},
                             {"--report", line.report},
                             {"--preview", line.preview}};
    for (const NamedFile& file : all)
        if (!file.path.empty()) files.push_back(file);
    return files;
}

const char* usage_text() { return kUsage; }

const char* axis_name(stratmesh::Axis axis) {
    const struct {
        stratmesh::Axis axis;
        const char* name;
    } names[] = {{stratmesh::Axis::automatic, "automatic"},
                 {stratmesh::Axis::x, "x"},
                 {stratmesh::Axis::y, "y"},
                 {stratmesh::Axis::z, "z"},
                 {stratmesh::Axis::direction, "direction"}};
    for (const auto& n : names)
        if (n.axis == axis) return n.name;
    return "unknown";
}

const char* parts_name(stratmesh::Parts parts) {
    switch (parts) {
        case stratmesh::Parts::automatic: return "automatic";
        case stratmesh::Parts::one_tube: return "one-tube";
        case stratmesh::Parts::apart: return "apart";
    }
    return "unknown";
}

} // namespace stratmesh_cli
