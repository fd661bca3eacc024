// bench_clouds.h - the benchmark's 3D point clouds for stratmesh::reconstruct.
//
// Every generator fills `xyz` with x y z triples from a size and a seed, deterministically:
// the random numbers are the benchmark's own SplitMix64 (bench_random.h); the shapes go
// through the C library's sin, cos, exp and sqrt.

#ifndef STRATMESH_BENCH_CLOUDS_H
#define STRATMESH_BENCH_CLOUDS_H

#include <cstddef>
#include <cstdint>
#include <vector>

namespace bench {

// The star-shaped bumpy tube r = 1 + 0.25 sin(5 theta) cos(z) around the z axis,
// z in [0, 8]: n points with (theta, z) uniform in [0, 2 pi) x [0, 8].
void generate_tube(size_t n, uint64_t seed, std::vector<double>& xyz);

// Layering comparisons: a vase r = 1 + 0.5 sin(1.5 z), z in [-3, 3], whose
// calmest sections (radius extremes) are at z = -pi/3 and pi/3 (kVaseCuts); and a
// unit tube over z in [-6, 6] whose centre line bends to x = 2 sin(pi z / 12), so no
// straight line runs inside all of it (kBentTubeCuts: five equal layers, the fewest equal
// layers found by hand to give no fold).
extern const double kVaseCuts[2];
extern const double kBentTubeCuts[4];
void generate_vase(size_t n, uint64_t seed, std::vector<double>& xyz);
void generate_bent_tube(size_t n, uint64_t seed, std::vector<double>& xyz);

// The shapes of the three experiments of the 2014 paper (Xiao, Deng, Li; section 2), made
// up from the paper's point counts, height ranges and cut heights only (the paper's
// clouds are not public). n is the point count; the paper's are below.

// A head on its neck, z in [21.88, 305.35] mm: a neck, a jaw, a face with a chin, mouth,
// nose, eye sockets, brow and ears, a wider skull, and a crown that narrows but stays open
// (a column, like the paper's). Mouth, nose, eyes and ears are sampled three to four times
// denser than the rest, as in a scan.
const size_t kHeadPoints = 12772;
extern const double kHeadCuts[5];  // 68, 74, 135, 210, 270 (the paper's layers L1-L6)
void generate_paper_head(size_t n, uint64_t seed, std::vector<double>& xyz);

// A right ventricle from CT: planar contours 0.5 mm apart, z = 0, 0.5, ..., 44 (89
// contours), every point of a contour at exactly its height. Kidney-shaped sections
// (the septum pushes in) that grow from the apex at z = 0 to the base at z = 44 along a
// slightly tilted centre line. Each contour gets a share of the n points proportional to
// its length, at equal angular steps from a random starting angle.
const size_t kVentriclePoints = 13845;
extern const double kVentricleCuts[2];  // 15, 30 (L1-L3)
void generate_paper_ventricle(size_t n, uint64_t seed, std::vector<double>& xyz);

// A skull, z in [-10.6, 7.5]: a narrow jaw at the bottom (open), cheekbones, eye sockets
// and a nasal opening at the front, ear bumps at the sides, and a CLOSED dome on top (the
// crown reaches the axis at z = 7.5). Eyes, ears and cheekbones are sampled three times
// denser than the rest.
const size_t kSkullPoints = 20001;
extern const double kSkullCuts[3];  // -3, 1, 4 (L1-L4)
void generate_paper_skull(size_t n, uint64_t seed, std::vector<double>& xyz);

}  // namespace bench

#endif  // STRATMESH_BENCH_CLOUDS_H
