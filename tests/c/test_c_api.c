/* The C interface from C99: reconstruct and the stream on a tube, checked as a mesh (every
 * point a vertex, each edge on two triangles once capped, one orientation), the report's
 * counts, the statuses of bad input, and guard bytes after every buffer the library
 * writes. Exits non-zero on the first failed check. */
#include "stratmesh.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RINGS 24
#define PER_RING 32
#define POINTS (RINGS * PER_RING)
#define RING_GAP 0.2
#define LAYERS 4
#define GUARD 64
#define GUARD_BYTE 0xA5

static int failures = 0;

#define CHECK(cond)                                                            \
    do {                                                                       \
        if (!(cond)) {                                                         \
            fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
            ++failures;                                                        \
        }                                                                      \
    } while (0)

/* A buffer of `bytes` followed by GUARD bytes of a known value. */
static unsigned char* guarded(size_t bytes) {
    unsigned char* p = (unsigned char*)malloc(bytes + GUARD);
    if (!p) {
        fprintf(stderr, "out of memory\n");
        exit(2);
    }
    memset(p, 0, bytes);
    memset(p + bytes, GUARD_BYTE, GUARD);
    return p;
}

/* The test's POINTS points, packed doubles. */
static stratmesh_cloud packed_cloud(const double* xyz) {
    stratmesh_cloud cloud;
    cloud.xyz = xyz;
    cloud.count = POINTS;
    cloud.stride_bytes = 0;
    cloud.scalar = STRATMESH_SCALAR_FLOAT64;
    return cloud;
}

static int guard_intact(const unsigned char* p, size_t bytes) {
    size_t i;
    for (i = 0; i < GUARD; ++i)
        if (p[bytes + i] != GUARD_BYTE) return 0;
    return 1;
}

/* A tube of radius about 1 along z: rings 0.2 apart, every other one turned by half a
 * step, radii jittered by up to 1% (a fixed generator), so no four points are cocircular
 * on the unrolled cylinder. Ring by ring, so in ascending z. */
static void make_tube(double* xyz) {
    const double pi = 3.14159265358979323846;
    unsigned long state = 12345u;
    int ring, k;
    for (ring = 0; ring < RINGS; ++ring) {
        for (k = 0; k < PER_RING; ++k) {
            double angle = 2 * pi * (k + 0.5 * (ring % 2)) / PER_RING;
            double radius;
            state = (state * 1103515245u + 12345u) & 0x7fffffffu;
            radius = 1.0 + 0.01 * ((double)(state % 1000u) / 1000.0 - 0.5);
            xyz[3 * (ring * PER_RING + k)] = radius * cos(angle);
            xyz[3 * (ring * PER_RING + k) + 1] = radius * sin(angle);
            xyz[3 * (ring * PER_RING + k) + 2] = RING_GAP * ring;
        }
    }
}

static int compare_edges(const void* a, const void* b) {
    const uint64_t x = *(const uint64_t*)a, y = *(const uint64_t*)b;
    return x < y ? -1 : x > y ? 1 : 0;
}

/* Checks the mesh: indices in range, no degenerate triangle, every point a vertex, each
 * undirected edge on exactly two triangles (closed) or at most two, and each directed edge
 * on one triangle at most (one orientation). */
static void check_mesh(const uint32_t* tris, size_t count, size_t points, int closed) {
    uint64_t* directed = (uint64_t*)malloc(3 * count * sizeof(uint64_t));
    uint64_t* undirected = (uint64_t*)malloc(3 * count * sizeof(uint64_t));
    unsigned char* seen = (unsigned char*)calloc(points, 1);
    size_t t, i, run, bad_index = 0, degenerate = 0, unseen = 0, over = 0, odd = 0, repeat = 0;
    if (!directed || !undirected || !seen) exit(2);
    for (t = 0; t < count; ++t) {
        for (i = 0; i < 3; ++i) {
            uint32_t a = tris[3 * t + i], b = tris[3 * t + (i + 1) % 3];
            if (a >= points || b >= points) {
                ++bad_index;
                a = b = 0;
            }
            if (a == b) ++degenerate;
            seen[a] = 1;
            directed[3 * t + i] = ((uint64_t)a << 32) | b;
            undirected[3 * t + i] = a < b ? ((uint64_t)a << 32) | b : ((uint64_t)b << 32) | a;
        }
    }
    for (i = 0; i < points; ++i) unseen += !seen[i];
    qsort(directed, 3 * count, sizeof(uint64_t), compare_edges);
    qsort(undirected, 3 * count, sizeof(uint64_t), compare_edges);
    for (i = 1; i < 3 * count; ++i) repeat += directed[i] == directed[i - 1];
    for (i = 0; i < 3 * count; i += run) {
        for (run = 1; i + run < 3 * count && undirected[i + run] == undirected[i]; ++run) {}
        if (run > 2) ++over;
        if (closed && run != 2) ++odd;
    }
    CHECK(bad_index == 0);
    CHECK(degenerate == 0);
    CHECK(unseen == 0);
    CHECK(over == 0);
    CHECK(odd == 0);
    CHECK(repeat == 0);
    free(directed);
    free(undirected);
    free(seen);
}

static void check_counts(const stratmesh_report* r) {
    CHECK(r->points.in_count == r->points.used_count + r->points.duplicate_count +
                                    r->points.rejected_count + r->points.unused_count);
    CHECK(r->points.outlier_count <= r->points.rejected_count);
}

static void test_reconstruct(const double* xyz, int add_caps) {
    stratmesh_cloud cloud;
    stratmesh_options options;
    stratmesh_report report;
    stratmesh_layer_info* layers;
    unsigned char* work;
    uint32_t* tris;
    size_t work_bytes, max_tris, count = 0, k;
    stratmesh_status status;

    memset(&options, 0, sizeof options);
    options.axis = STRATMESH_AXIS_Z;
    options.layer_count = LAYERS;
    if (add_caps) options.flags = STRATMESH_FLAG_ADD_CAPS;
    cloud = packed_cloud(xyz);

    work_bytes = stratmesh_reconstruct_workspace_size(POINTS, &options);
    max_tris = stratmesh_reconstruct_max_triangles(POINTS, &options);
    CHECK(work_bytes > 0);
    CHECK(max_tris >= 2 * POINTS);
    work = guarded(work_bytes);
    tris = (uint32_t*)guarded(3 * max_tris * sizeof(uint32_t));
    layers = (stratmesh_layer_info*)guarded(LAYERS * sizeof(stratmesh_layer_info));
    memset(&report, 0, sizeof report);
    report.layers.info = layers;
    report.layers.info_capacity = LAYERS;

    status = stratmesh_reconstruct(&cloud, &options, work, work_bytes, tris, max_tris, &count,
                                   &report);
    CHECK(status == STRATMESH_STATUS_OK);
    CHECK(count > 0 && count <= max_tris);
    CHECK(report.triangle_count == count);
    CHECK(report.points.in_count == POINTS);
    CHECK(report.points.used_count == POINTS);
    check_counts(&report);
    CHECK(report.workspace_used_bytes > 0 && report.workspace_used_bytes <= work_bytes);
    CHECK(fabs(report.axis[2]) == 1.0);
    CHECK(report.layers.info == layers);
    CHECK(report.layers.used_count >= 1 && report.layers.used_count <= LAYERS);
    for (k = 0; k < report.layers.used_count; ++k) {
        CHECK(layers[k].bottom < layers[k].top);
        CHECK(layers[k].point_count > 0);
        CHECK(layers[k].radius > 0.9 && layers[k].radius < 1.1);
        if (k > 0) CHECK(layers[k - 1].top <= layers[k].bottom);
    }
    CHECK(report.diagnostics.fold_count == 0);
    /* A tube follows its cloud: measured, no crossing pair, a misfit share far under the
       poor one. */
    CHECK(report.diagnostics.fit_sample_count > 0 && report.diagnostics.point_spacing > 0);
    CHECK(report.diagnostics.crossing_pair_count == 0 && report.diagnostics.crossing_check_complete == 1);
    CHECK(report.diagnostics.misfit_area_fraction < STRATMESH_POOR_MISFIT_FRACTION / 5);
    CHECK(report.parts.outcome == STRATMESH_PARTS_OUTCOME_ONE_TUBE);
    if (add_caps) {
        CHECK(report.caps.closed_count == 2);
        CHECK(report.caps.open_count == 0);
        /* A closed surface through V points: 2V - 4 triangles (Euler characteristic 2). */
        CHECK(count == 2 * (size_t)POINTS - 4);
    } else {
        CHECK(report.caps.closed_count == 0 && report.caps.triangle_count == 0);
        /* An open tube, two loops of PER_RING points: V - E + F = 0. */
        CHECK(count == 2 * (size_t)POINTS - 2 * PER_RING);
    }
    check_mesh(tris, count, POINTS, add_caps);
    CHECK(guard_intact(work, work_bytes));
    CHECK(guard_intact((unsigned char*)tris, 3 * max_tris * sizeof(uint32_t)));
    CHECK(guard_intact((unsigned char*)layers, LAYERS * sizeof(stratmesh_layer_info)));
    free(work);
    free(tris);
    free(layers);
}

/* Bad input: each returns its documented status and writes nothing past its buffers. */
static void test_bad_input(double* xyz) {
    stratmesh_cloud cloud;
    stratmesh_options options;
    stratmesh_report report;
    unsigned char* work;
    uint32_t* tris;
    size_t work_bytes, max_tris, count, small;
    stratmesh_status status;
    const double saved = xyz[3 * 100 + 1];

    memset(&options, 0, sizeof options);
    options.axis = STRATMESH_AXIS_Z;
    options.layer_count = LAYERS;
    cloud.xyz = xyz;
    cloud.count = POINTS;
    cloud.stride_bytes = 3 * sizeof(double);
    cloud.scalar = STRATMESH_SCALAR_FLOAT64;
    work_bytes = stratmesh_reconstruct_workspace_size(POINTS, &options);
    max_tris = stratmesh_reconstruct_max_triangles(POINTS, &options);
    work = guarded(work_bytes);
    tris = (uint32_t*)guarded(3 * max_tris * sizeof(uint32_t));

    /* A NaN coordinate: refused with its index, then skipped with the flag. */
    xyz[3 * 100 + 1] = nan("");
    memset(&report, 0, sizeof report);
    count = 99;
    status = stratmesh_reconstruct(&cloud, &options, work, work_bytes, tris, max_tris, &count,
                                   &report);
    CHECK(status == STRATMESH_STATUS_INVALID_POINT);
    CHECK(report.points.first_invalid_index == 100);
    CHECK(count == 0);
    check_counts(&report);
    options.flags = STRATMESH_FLAG_SKIP_INVALID_POINTS;
    memset(&report, 0, sizeof report);
    status = stratmesh_reconstruct(&cloud, &options, work, work_bytes, tris, max_tris, &count,
                                   &report);
    CHECK(status == STRATMESH_STATUS_OK);
    CHECK(report.points.rejected_count == 1);
    CHECK(report.points.used_count == POINTS - 1);
    check_counts(&report);
    options.flags = 0;
    xyz[3 * 100 + 1] = saved;

    /* No points. */
    cloud.count = 0;
    memset(&report, 0, sizeof report);
    status = stratmesh_reconstruct(&cloud, &options, work, work_bytes, tris, max_tris, &count,
                                   &report);
    CHECK(status == STRATMESH_STATUS_TOO_FEW_POINTS);
    CHECK(count == 0 && report.points.in_count == 0);
    cloud.count = POINTS;

    /* A workspace a quarter of the bound: refused, nothing written past it. */
    free(work);
    small = work_bytes / 4;
    work = guarded(small);
    memset(&report, 0, sizeof report);
    status = stratmesh_reconstruct(&cloud, &options, work, small, tris, max_tris, &count,
                                   &report);
    CHECK(status == STRATMESH_STATUS_OUT_OF_MEMORY);
    CHECK(count == 0);
    CHECK(guard_intact(work, small));
    check_counts(&report);
    free(work);
    work = guarded(work_bytes);

    /* Too few triangles: the count needed, nothing written past the array's end. */
    free(tris);
    tris = (uint32_t*)guarded(3 * 100 * sizeof(uint32_t));
    status = stratmesh_reconstruct(&cloud, &options, work, work_bytes, tris, 100, &count,
                                   &report);
    CHECK(status == STRATMESH_STATUS_TRIANGLE_CAPACITY);
    CHECK(report.triangle_count > 100);
    CHECK(guard_intact((unsigned char*)tris, 3 * 100 * sizeof(uint32_t)));
    CHECK(guard_intact(work, work_bytes));

    /* A NULL cloud, a report inside the workspace: refused, nothing written at all. */
    CHECK(stratmesh_reconstruct(NULL, &options, work, work_bytes, tris, 100, &count, &report) ==
          STRATMESH_STATUS_INVALID_ARGUMENT);
    memset(work, 0x3C, work_bytes);
    status = stratmesh_reconstruct(&cloud, &options, work, work_bytes, tris, 100, &count,
                                   (stratmesh_report*)(void*)(work + 64));
    CHECK(status == STRATMESH_STATUS_INVALID_ARGUMENT);
    {
        size_t i, changed = 0;
        for (i = 0; i < work_bytes; ++i) changed += work[i] != 0x3C;
        CHECK(changed == 0);
    }

    /* An unknown axis and scalar. */
    options.axis = 17;
    CHECK(stratmesh_reconstruct(&cloud, &options, work, work_bytes, tris, 100, &count, NULL) ==
          STRATMESH_STATUS_INVALID_AXIS);
    options.axis = STRATMESH_AXIS_Z;
    cloud.scalar = 9;
    CHECK(stratmesh_reconstruct(&cloud, &options, work, work_bytes, tris, 100, &count, NULL) ==
          STRATMESH_STATUS_INVALID_ARGUMENT);
    free(work);
    free(tris);
}

static void test_status_strings(void) {
    CHECK(strncmp(stratmesh_status_string(STRATMESH_STATUS_OK), "ok:", 3) == 0);
    CHECK(strncmp(stratmesh_status_string(STRATMESH_STATUS_INVALID_POINT), "invalid_point:", 14) == 0);
    CHECK(strncmp(stratmesh_status_string(STRATMESH_STATUS_INTERNAL_ERROR), "internal_error:", 15) == 0);
    CHECK(strcmp(stratmesh_status_string(99), "unknown status") == 0);
}

/* The stream's triangles, collected from its callback. */
typedef struct collected {
    uint32_t* tris;
    size_t count, capacity, calls;
} collected;

static void collect(void* user, const uint32_t* tris, size_t count) {
    collected* c = (collected*)user;
    size_t i;
    ++c->calls;
    for (i = 0; i < 3 * count && 3 * c->count + i < 3 * c->capacity; ++i)
        c->tris[3 * c->count + i] = tris[i];
    c->count += count;
}

/* Pushed ring after ring in LAYERS pushes, the stream gives the triangles of
 * stratmesh_reconstruct with the cuts at the pushes' tops and the same origin, in order. */
static void test_stream(const double* xyz) {
    const size_t rings_per_push = RINGS / LAYERS;
    double cuts[LAYERS - 1];
    stratmesh_options options;
    stratmesh_report report, stream_report;
    stratmesh_cloud cloud;
    stratmesh_stream* stream = NULL;
    collected got;
    unsigned char *work, *stream_work;
    uint32_t* tris;
    size_t work_bytes, stream_bytes, max_tris, count = 0, k;
    stratmesh_status status;

    for (k = 0; k + 1 < LAYERS; ++k) cuts[k] = RING_GAP * ((double)((k + 1) * rings_per_push) - 0.5);
    memset(&options, 0, sizeof options);
    options.axis = STRATMESH_AXIS_Z;
    options.flags = STRATMESH_FLAG_ORIGIN_GIVEN;
    options.origin[0] = xyz[0];
    options.origin[1] = xyz[1];
    options.origin[2] = xyz[2];

    /* The reference: reconstruct with the same cuts. */
    options.cuts = cuts;
    options.cut_count = LAYERS - 1;
    cloud = packed_cloud(xyz);
    work_bytes = stratmesh_reconstruct_workspace_size(POINTS, &options);
    max_tris = stratmesh_reconstruct_max_triangles(POINTS, &options);
    work = guarded(work_bytes);
    tris = (uint32_t*)guarded(3 * max_tris * sizeof(uint32_t));
    memset(&report, 0, sizeof report);
    status = stratmesh_reconstruct(&cloud, &options, work, work_bytes, tris, max_tris, &count,
                                   &report);
    CHECK(status == STRATMESH_STATUS_OK);
    CHECK(report.layers.used_count == LAYERS);
    options.cuts = NULL;
    options.cut_count = 0;

    /* The stream, in a workspace for three pushes, starting at an odd address. */
    stream_bytes = stratmesh_stream_workspace_size(3 * rings_per_push * PER_RING, &options);
    CHECK(stream_bytes > 0);
    stream_work = guarded(stream_bytes + 1);
    got.tris = (uint32_t*)guarded(3 * max_tris * sizeof(uint32_t));
    got.count = got.calls = 0;
    got.capacity = max_tris;
    memset(&stream_report, 0, sizeof stream_report);
    status = stratmesh_stream_open(&options, stream_work + 1, stream_bytes, collect, &got,
                                   &stream_report, &stream);
    CHECK(status == STRATMESH_STATUS_OK);
    CHECK(stream != NULL);
    if (status != STRATMESH_STATUS_OK) return;
    for (k = 0; k < LAYERS; ++k) {
        stratmesh_cloud push;
        push.xyz = xyz + 3 * k * rings_per_push * PER_RING;
        push.count = rings_per_push * PER_RING;
        push.stride_bytes = 0;
        push.scalar = STRATMESH_SCALAR_FLOAT64;
        status = stratmesh_stream_push(stream, &push, k + 1 < LAYERS ? cuts[k] : 100.0);
        CHECK(status == STRATMESH_STATUS_OK);
        CHECK(stream_report.points.in_count == (k + 1) * rings_per_push * PER_RING);
        check_counts(&stream_report);
    }
    /* A push below the last top is out of order, and changes nothing. */
    {
        stratmesh_cloud low;
        low.xyz = xyz;
        low.count = PER_RING;
        low.stride_bytes = 0;
        low.scalar = STRATMESH_SCALAR_FLOAT64;
        CHECK(stratmesh_stream_push(stream, &low, 101.0) == STRATMESH_STATUS_OUT_OF_ORDER);
        CHECK(stream_report.points.in_count == POINTS);
    }
    status = stratmesh_stream_close(stream);
    CHECK(status == STRATMESH_STATUS_OK);
    CHECK(stratmesh_stream_close(stream) == STRATMESH_STATUS_INVALID_ARGUMENT);
    CHECK(got.calls > 1);
    CHECK(got.count == count);
    CHECK(stream_report.triangle_count == count);
    CHECK(stream_report.points.used_count == POINTS);
    CHECK(stream_report.layers.used_count == LAYERS);
    CHECK(stream_report.points.held_count > 0 &&
          stream_report.points.held_count <= 3 * rings_per_push * PER_RING);
    check_counts(&stream_report);
    CHECK(got.count == count && memcmp(got.tris, tris, 3 * count * sizeof(uint32_t)) == 0);
    CHECK(guard_intact(stream_work, stream_bytes + 1));
    CHECK(guard_intact((unsigned char*)got.tris, 3 * max_tris * sizeof(uint32_t)));

    /* Refusals at open: the automatic axis, a workspace too small for the handle. */
    options.axis = STRATMESH_AXIS_AUTOMATIC;
    CHECK(stratmesh_stream_open(&options, stream_work, stream_bytes, collect, &got, NULL,
                                &stream) == STRATMESH_STATUS_INVALID_AXIS);
    CHECK(stream == NULL);
    options.axis = STRATMESH_AXIS_Z;
    CHECK(stratmesh_stream_open(&options, stream_work, 16, collect, &got, NULL, &stream) ==
          STRATMESH_STATUS_OUT_OF_MEMORY);
    CHECK(guard_intact(stream_work, stream_bytes + 1));
    options.flags |= STRATMESH_FLAG_ADD_CAPS;
    CHECK(stratmesh_stream_open(&options, stream_work, stream_bytes, collect, &got, NULL,
                                &stream) == STRATMESH_STATUS_INVALID_ARGUMENT);
    free(work);
    free(tris);
    free(stream_work);
    free(got.tris);
}

/* The 2D triangulation of a 4 x 4 grid: 2n - 2 - h = 18 triangles, all counter-clockwise. */
static void test_delaunay(void) {
    double xy[2 * 16];
    stratmesh_delaunay_2d_info info;
    unsigned char* work;
    uint32_t* tris;
    size_t work_bytes = stratmesh_delaunay_2d_workspace_size(16);
    size_t max_tris = stratmesh_delaunay_2d_max_triangles(16);
    size_t t;
    int i;
    for (i = 0; i < 16; ++i) {
        xy[2 * i] = i % 4;
        xy[2 * i + 1] = i / 4;
    }
    CHECK(max_tris == 27);
    work = guarded(work_bytes);
    tris = (uint32_t*)guarded(3 * max_tris * sizeof(uint32_t));
    CHECK(stratmesh_delaunay_2d(xy, 16, 2 * sizeof(double), work, work_bytes, tris, max_tris,
                                &info, NULL) == STRATMESH_STATUS_OK);
    CHECK(info.triangle_count == 18);
    CHECK(info.hull_vertex_count == 12);
    for (t = 0; t < info.triangle_count && t < max_tris; ++t)
        CHECK(stratmesh_orient2d(&xy[2 * tris[3 * t]], &xy[2 * tris[3 * t + 1]],
                                 &xy[2 * tris[3 * t + 2]]) > 0);
    CHECK(guard_intact(work, work_bytes));
    CHECK(guard_intact((unsigned char*)tris, 3 * max_tris * sizeof(uint32_t)));
    free(work);
    free(tris);
}

int main(void) {
    double* xyz = (double*)malloc(3 * POINTS * sizeof(double));
    if (!xyz) return 2;
    make_tube(xyz);
    test_status_strings();
    test_reconstruct(xyz, 0);
    test_reconstruct(xyz, 1);
    test_bad_input(xyz);
    test_stream(xyz);
    test_delaunay();
    free(xyz);
    if (failures) {
        fprintf(stderr, "%d checks failed\n", failures);
        return 1;
    }
    printf("C interface: all checks passed\n");
    return 0;
}
