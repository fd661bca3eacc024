// >>config restore ==========================================================================
// Undoes what >>config set: its helper macros and the pinned contraction.

#undef STRATMESH_SMALL_NOINLINE
#undef STRATMESH_FAST_NOINLINE
#undef STRATMESH_NOINLINE

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC pop_options
#elif defined(__clang__)
#pragma STDC FP_CONTRACT DEFAULT
#endif
