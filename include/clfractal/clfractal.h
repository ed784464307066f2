/* clfractal C ABI: the isosurface fractal dimension of 3D scalar grids from C (or any
 * language with a C FFI).
 *
 * Conventions:
 *  - Objects are opaque handles created by clf_*_create / clf_*_read / clf_*_compute and
 *    released by the matching clf_*_destroy (which accepts NULL).
 *  - Every function that can fail returns a clf_status; CLF_OK is 0. On failure the
 *    thread's last-error message (clf_last_error) names the input and the problem, and
 *    output handles are left NULL. No C++ exception crosses this boundary.
 *  - Every entry point checks its arguments: a NULL handle or pointer, and a type or kind
 *    outside its enum, is CLF_ERROR_INPUT (a getter returns its documented fallback and
 *    sets the last-error message). Types and kinds are passed as int and checked before
 *    they are converted, so any int is safe to pass.
 *  - After every call (except clf_last_error and clf_version), clf_last_error() describes
 *    that call: "" when it succeeded.
 *  - A failed host or device allocation is CLF_ERROR_OUT_OF_MEMORY, never a crash.
 *
 * Lifetime: a handle is valid from the call that creates it until its clf_*_destroy;
 * destroying NULL does nothing, destroying twice or using a destroyed handle is undefined.
 * Curves and volumes do not refer to the context or volume they came from (each may be
 * destroyed in any order); a stream needs its context until clf_stream_destroy. Strings
 * returned (clf_version, clf_last_error, clf_context_description) live until the next call
 * on the same thread (clf_last_error), until the context is destroyed (the description), or
 * forever (the version).
 *
 * Threads: any number of threads may call the library at once. Objects are not locked:
 * one thread at a time per clf_volume being created, per clf_curve and per clf_stream, but
 * read-only calls (getters, a volume passed as input) may share an object freely. A
 * clf_context may be shared by threads (its kernel cache is locked; launches on it are
 * serialised by its queue); one context per thread gives independent queues. The
 * last-error message is per thread.
 *  - Volumes are x fastest: value (x, y, z) sits at x + nx * (y + ny * z).
 *  - Definitions (intersection a < s <= b, isovalue sets, subsampling, dimensions) are
 *    those of the C++ library: see docs/definitions.md and the headers in include/clfractal.
 */
#ifndef CLFRACTAL_H
#define CLFRACTAL_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum clf_status {
    CLF_OK = 0,
    CLF_ERROR_INPUT = 1,         /* bad input: file, dimensions, NaN, argument */
    CLF_ERROR_OUT_OF_MEMORY = 2, /* the device or the host is out of memory */
    CLF_ERROR_DEVICE = 3,        /* an OpenCL failure (message carries the error name) */
    CLF_ERROR_INTERNAL = 4       /* anything else */
} clf_status;

/* Value types. float64 needs a device with cl_khr_fp64 (else CLF_ERROR_INPUT naming it). */
typedef enum clf_type {
    CLF_TYPE_NONE = -1, /* clf_volume_type of NULL */
    CLF_UINT8 = 0,
    CLF_UINT16 = 1,
    CLF_INT16 = 2,
    CLF_FLOAT32 = 3,
    CLF_INT8 = 4,
    CLF_INT32 = 5,
    CLF_UINT32 = 6,
    CLF_FLOAT64 = 7
} clf_type;

/* Box dimension counts intersected cubes (eq. 2.5), edge dimension grid edges (eq. 3.1). */
typedef enum clf_kind { CLF_BOX = 0, CLF_EDGE = 1 } clf_kind;

typedef struct clf_context clf_context; /* an OpenCL device with its compiled kernels */
typedef struct clf_volume clf_volume;   /* a host volume */
typedef struct clf_curve clf_curve;     /* a fractal dimension curve over isovalues */
typedef struct clf_stream clf_stream;   /* a volume arriving slice by slice */
typedef struct clf_components_stream clf_components_stream; /* component counts, slice by slice */

/* Options of a curve. Zero-initialise and set what you need; clf_curve_options_default
 * gives box dimension, 2 levels (eq. 2.5), default isovalues (every integer of the value
 * range when it holds at most 65,536 integers, else 256 uniform values: float32 values for
 * float32 data, float64 values for the others). */
typedef struct clf_curve_options {
    int kind;                /* a clf_kind */
    int levels;              /* pyramid levels 0..levels-1, >= 2; 2 = the thesis' ratio */
    size_t bins;             /* float and int32/uint32 data: number of uniform isovalues (0: 256) */
    const float* isovalues;  /* float and int32/uint32 data: an explicit sorted list instead of
                                bins (float64 isovalues with these values for float64, int32
                                and uint32 data) */
    size_t isovalue_count;
} clf_curve_options;

typedef struct clf_summary {
    size_t defined;       /* isovalues where the dimension is defined (and counts >= min_count) */
    double mean, std;     /* mean and population std of D(s) over them (NaN when none) */
    double weighted_mean; /* mean weighted by the full-grid count */
    double kappa;         /* growth exponent mean / 3 */
} clf_summary;

/* The library version, "MAJOR.MINOR.PATCH". */
const char* clf_version(void);

/* The message of the calling thread's last call: "" if it succeeded, else what failed.
 * Valid until the next call on this thread. */
const char* clf_last_error(void);

/* ---- device context ---- */

/* A context on the device whose platform or device name contains `device_filter`
 * (case-insensitive); NULL or "" picks the default (environment CLFRACTAL_DEVICE /
 * CLFRACTAL_DEVICE_TYPE, else the first GPU, else the first device). No device that
 * matches: CLF_ERROR_DEVICE, the message naming the filter and every device. */
clf_status clf_context_create(const char* device_filter, clf_context** out);
void clf_context_destroy(clf_context* ctx);
/* "platform / device", valid while the context lives. */
const char* clf_context_description(const clf_context* ctx);

/* ---- volumes ---- */

/* Reads any volume read_volume reads (NRRD, DICOM series directory, NIfTI, TIFF, MetaImage,
   NAME_XxYxZ_TYPE.raw) or "synthetic:NAME[:N]". */
clf_status clf_volume_read(const char* path, clf_volume** out);
/* A volume holding a copy of `data` (nx * ny * nz values of `type`, x fastest). Float
 * data containing NaN or Inf is rejected. */
clf_status clf_volume_create(const void* data, size_t nx, size_t ny, size_t nz, int type, clf_volume** out);
void clf_volume_destroy(clf_volume* volume);
void clf_volume_dims(const clf_volume* volume, size_t dims[3]);
/* The volume's clf_type; CLF_TYPE_NONE for NULL. */
clf_type clf_volume_type(const clf_volume* volume);

/* ---- fractal dimension curves ---- */

void clf_curve_options_default(clf_curve_options* options);
/* Counts every isovalue at once on the device and forms the curve. options may be NULL. */
clf_status clf_curve_compute(clf_context* ctx, const clf_volume* volume, const clf_curve_options* options,
                             clf_curve** out);
void clf_curve_destroy(clf_curve* curve);
size_t clf_curve_size(const clf_curve* curve);
int clf_curve_levels(const clf_curve* curve);
double clf_curve_isovalue(const clf_curve* curve, size_t j);
/* D(s_j) from levels 0 and 1 (NaN where undefined). */
double clf_curve_dimension(const clf_curve* curve, size_t j);
/* The least-squares dimension over all levels (equals clf_curve_dimension for 2 levels). */
double clf_curve_dimension_fit(const clf_curve* curve, size_t j);
/* Intersected cubes (or edges) of level `level` at isovalue j. */
uint64_t clf_curve_count(const clf_curve* curve, int level, size_t j);
/* Summary over the isovalues where D is defined and the level-1 count is >= min_count. */
void clf_curve_summary(const clf_curve* curve, uint64_t min_count, clf_summary* out);

/* ---- slice streaming (scanner pipelines): memory for a few slices only ---- */

/* A stream of nx * ny slices of `type`, pushed in z order. Its isovalues: options->isovalues
 * (float and int32/uint32 data), else for integer data the default set of `range` = {min,
 * max} (NULL: the type's whole range; an integer range is clipped to the type's values): every integer when it holds at most 65,536, else
 * options->bins (default 256) uniform values; for float data options->bins uniform values
 * over `range` (required, since the stream cannot know the values to come). options->levels as for
 * curves; both kinds (box and edge) are counted. */
clf_status clf_stream_create(clf_context* ctx, size_t nx, size_t ny, int type, const clf_curve_options* options,
                             const double* range, clf_stream** out);
void clf_stream_destroy(clf_stream* stream);
/* Adds the next slice: nx * ny values of the stream's type, x fastest. Float slices with
 * NaN or Inf are rejected (CLF_ERROR_INPUT) and not added. */
clf_status clf_stream_push_slice(clf_stream* stream, const void* slice);
size_t clf_stream_slices(const clf_stream* stream);
/* The curve of the slices pushed so far (at least 2 are needed for a cube), identical to
 * clf_curve_compute on the volume of those slices; the stream goes on afterwards. */
clf_status clf_stream_curve(const clf_stream* stream, int kind, clf_curve** out);

/* ---- isosurface components at a few isovalues, slice by slice (docs/definitions.md §19) ---- */

/* Connectivity of the component counts: CLF_COMPONENTS_CUBE {f < s} 6- and {f >= s}
 * 26-connected (marching cubes), CLF_COMPONENTS_FREUDENTHAL both 14-connected (marching
 * tetrahedra). */
typedef enum clf_connectivity { CLF_COMPONENTS_CUBE = 0, CLF_COMPONENTS_FREUDENTHAL = 1 } clf_connectivity;

/* A stream of nx * ny slices of `type`, pushed in z order, counting the isosurface components
 * components(s) = b0({f < s}) + b0({f >= s}) - 1 (0 when either set is empty) at the `count`
 * finite isovalues (integer data: f >= ceil(s); float32 data: s rounded to float32). Runs on
 * the host (no context); memory O(slice) an isovalue. */
clf_status clf_components_stream_create(size_t nx, size_t ny, int type, const double* isovalues, size_t count,
                                        int connectivity, clf_components_stream** out);
void clf_components_stream_destroy(clf_components_stream* stream);
/* Adds the next `count` slices: nx * ny * count values of the stream's type, x fastest, then
 * y, then z. Float slices with NaN or Inf are CLF_ERROR_INPUT and add nothing. */
clf_status clf_components_stream_push(clf_components_stream* stream, const void* slices, size_t count);
size_t clf_components_stream_slices(const clf_components_stream* stream);
/* components(s) of the slices pushed so far at each isovalue, into out[0 .. count-1]: those
 * of the volume the slices make; the stream goes on afterwards. */
clf_status clf_components_stream_counts(const clf_components_stream* stream, int64_t* out);

/* ---- local fractal dimension (eq. 2.6) ---- */

/* Writes LD at every vertex for isovalue `iso` and even window `window` (8 is the
 * thesis' choice) into `out` (nx * ny * nz floats, NaN where undefined). */
clf_status clf_local_dimension(clf_context* ctx, const clf_volume* volume, double iso, int window, float* out);

/* ---- 4D fractal dimension (thesis 6.4): one number per volume, no isovalue ---- */

typedef struct clf_fd4 {
    double q;       /* bin width at level 0 (G' uses 2q) */
    double vmin;    /* bin origin: the smallest value of the volume */
    uint64_t i4_l0; /* I4(G, q) */
    uint64_t i4_l1; /* I4(G', 2q) */
    double d4;      /* log2(i4_l0 / i4_l1); NaN where either is 0 */
} clf_fd4;

/* D4 of `volume` with bin width `q` (0: the default, 1 for integer data and
 * (vmax - vmin) / 256 for float data). A q that is not finite, negative, or so small that
 * the bins overflow is CLF_ERROR_INPUT. */
clf_status clf_fd4_compute(clf_context* ctx, const clf_volume* volume, double q, clf_fd4* out);

/* ---- the analysis: which isovalue to use, how noisy the scan is, what denoising helps ----
 * (clfractal::analyse; the same recommendations as `clfractal fd` and `clfractal report`) */

typedef struct clf_analysis clf_analysis;

/* clean: D <= clean_fd; noisy: D >= noisy_fd; rough between; undefined where D is. */
typedef enum clf_verdict { CLF_VERDICT_CLEAN = 0, CLF_VERDICT_ROUGH = 1, CLF_VERDICT_NOISY = 2, CLF_VERDICT_UNDEFINED = 3 } clf_verdict;

typedef struct clf_analysis_options {
    double clean_fd;    /* default 2.2 */
    double noisy_fd;    /* default 2.5 */
    double clean_share; /* well-populated: I(s) >= clean_share x the largest; default 0.01 */
    size_t bins;        /* uniform isovalues of float and wide data; default 256 */
    int components;     /* 0: none, 1: at the recommended isovalues (default), 2: the whole curve */
    int noise_level;    /* nonzero: noise.sigma and Theorem 1 inverted per isovalue (default 1) */
    int fd4;            /* nonzero: the 4D dimension (default 0) */
    int denoise;        /* nonzero: when nothing is clean, try the denoising ladder (default 1) */
    int window;         /* LD window of the targeted filter (default 8) */
} clf_analysis_options;

typedef struct clf_recommendation {
    double isovalue;
    double fd;            /* NaN where undefined */
    uint64_t count;       /* I(s) */
    uint64_t count_sub;   /* I(s) on the subsampled grid */
    int64_t components;   /* -1 when not computed */
    int verdict;          /* clf_verdict */
    double first, last;   /* the band it represents */
} clf_recommendation;

void clf_analysis_options_default(clf_analysis_options* options);
/* The analysis of `volume`; options may be NULL (the defaults). A constant volume (no cube
 * intersected anywhere) is CLF_ERROR_INPUT. */
clf_status clf_analyse(clf_context* ctx, const clf_volume* volume, const clf_analysis_options* options,
                       clf_analysis** out);
void clf_analysis_destroy(clf_analysis* analysis);
/* Recommended isovalues, best first: at least 1. */
size_t clf_analysis_recommended(const clf_analysis* analysis);
clf_status clf_analysis_recommendation(const clf_analysis* analysis, size_t i, clf_recommendation* out);
/* 1 when a well-populated isovalue is clean, else 0 (then the first recommendation is the
 * cleanest, and the JSON's "denoise" says what makes the scan clean). */
int clf_analysis_clean(const clf_analysis* analysis);
/* noise.sigma in grey values; NaN when not computed or no block is usable. */
double clf_analysis_noise_sigma(const clf_analysis* analysis);
/* The noise level in full (docs/definitions.md §34); NaN where not computed or
 * n/a. */
typedef struct clf_noise_level {
    double sigma;          /* the noise's standard deviation, correlation allowed for */
    double sigma_white;    /* its white (vertex-to-vertex) part */
    double correlation[3]; /* the correlation model's width along x, y, z in voxels; 0: white */
    double spread[3];      /* the noise map's 10th, 50th and 90th percentiles */
    double flat_share;     /* the share of the voxels the estimate reads */
} clf_noise_level;
/* Fills `out`; CLF_ERROR_INPUT when analysis or out is NULL or the analysis has no noise
 * level (options.noise_level was 0). */
clf_status clf_analysis_noise_level(const clf_analysis* analysis, clf_noise_level* out);
/* The whole analysis as JSON (the schema of `clfractal fd --json`'s shared part), valid
 * while the analysis lives. */
const char* clf_analysis_json(const clf_analysis* analysis);
/* ---- small-components filter (Zhao & Wenger 2025; docs/guide/denoise.md) ---- */

/* Connectivity of the small-components filter: CLF_SMALL_CUBE {f >= s} 26-connected and
 * {f < s} 6-connected (marching cubes); CLF_SMALL_SIX both 6-connected (the paper's). */
typedef enum clf_small_connectivity { CLF_SMALL_CUBE = 0, CLF_SMALL_SIX = 1 } clf_small_connectivity;

typedef struct clf_small_components {
    double isovalue;           /* s in the data's type (integer data: ceil(s)) */
    uint64_t positive_before;  /* components of {f >= s} in the input */
    uint64_t negative_before;  /* components of {f < s} in the input */
    uint64_t positive_removed; /* components of {f >= s} with <= k vertices, set just below s */
    uint64_t negative_removed; /* then components of {f < s} with <= k vertices, set to s */
    uint64_t positive_after;   /* components of {f >= s} in the result */
    uint64_t negative_after;   /* components of {f < s} in the result */
    uint64_t changed;          /* vertices whose value differs from the input */
    double changed_share;      /* changed / vertices */
} clf_small_components;

/* Writes the small-components filter of `volume` at isovalue `iso` with size `k` to `out`
 * (nx * ny * nz values of the volume's type, x fastest; it may not overlap the volume), and
 * its counts to `stats` (may be NULL). An isovalue with no value of the type below it or
 * none at or above it (uint8 data at s <= 0 or s > 255) is CLF_ERROR_INPUT. */
clf_status clf_small_components_filter(const clf_volume* volume, double iso, uint64_t k, int connectivity, void* out,
                                       clf_small_components* stats);

#ifdef __cplusplus
}
#endif

#endif /* CLFRACTAL_H */
