// ==== Predicates ===========================================================================
//
// Points are double[2] (x, y). The returned value's sign is exact (see the robustness
// contract above); its magnitude is an approximation of the determinant.

// Twice the signed area of triangle abc: positive if a, b, c turn counter-clockwise,
// negative if clockwise, zero if collinear.
double orient2d(const double a[2], const double b[2], const double c[2]);

// Positive if d lies inside the circle through a, b, c (which must be counter-clockwise),
// negative if outside, zero if the four points are cocircular. If a, b, c are clockwise
// the sign is reversed.
double incircle(const double a[2], const double b[2], const double c[2], const double d[2]);
