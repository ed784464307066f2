/* The C ABI: the fractal dimension curve of a volume, from C.
 *
 *   c_api [VOLUME]
 *
 * Without VOLUME it builds a 64^3 sphere whose surface carries noise in one half, so
 * that the curve has a clean and a noisy part. Build against the installed package with
 *   cc c_api.c $(pkg-config --cflags --libs clfractal)
 */
#include <clfractal/clfractal.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

static int check(clf_status status, const char* what) {
    if (status == CLF_OK) return 0;
    fprintf(stderr, "c_api: %s failed (status %d): %s\n", what, (int)status, clf_last_error());
    return 1;
}

int main(int argc, char** argv) {
    clf_context* ctx = NULL;
    clf_volume* volume = NULL;
    clf_curve* curve = NULL;
    int rc = 1;

    if (check(clf_context_create(NULL, &ctx), "clf_context_create")) return 1;
    printf("clfractal %s on %s\n", clf_version(), clf_context_description(ctx));

    if (argc > 1) {
        if (check(clf_volume_read(argv[1], &volume), "clf_volume_read")) goto done;
    } else {
        const size_t n = 64;
        unsigned char* data = malloc(n * n * n);
        if (!data) goto done;
        unsigned state = 12345u;
        for (size_t z = 0; z < n; ++z)
            for (size_t y = 0; y < n; ++y)
                for (size_t x = 0; x < n; ++x) {
                    double dx = x - 31.5, dy = y - 31.5, dz = z - 31.5;
                    double v = 128.0 + 4.0 * (24.0 - sqrt(dx * dx + dy * dy + dz * dz));
                    state = state * 1664525u + 1013904223u;
                    if (x >= n / 2) v += ((double)(state >> 8) / 16777216.0 - 0.5) * 24.0; /* noise in x >= 32 */
                    data[x + n * (y + n * z)] = (unsigned char)(v < 0 ? 0 : v > 255 ? 255 : v);
                }
        clf_status s = clf_volume_create(data, n, n, n, CLF_UINT8, &volume);
        free(data);
        if (check(s, "clf_volume_create")) goto done;
    }

    clf_curve_options options;
    clf_curve_options_default(&options);
    options.kind = CLF_EDGE; /* edge span dimension, eq. 3.1 */
    if (check(clf_curve_compute(ctx, volume, &options, &curve), "clf_curve_compute")) goto done;

    clf_summary summary;
    clf_curve_summary(curve, 0, &summary);
    size_t dims[3];
    clf_volume_dims(volume, dims);
    printf("%zux%zux%zu: %zu isovalues, dimension defined at %zu, mean %.4f, std %.4f\n", dims[0], dims[1], dims[2],
           clf_curve_size(curve), summary.defined, summary.mean, summary.std);
    for (size_t j = 0; j < clf_curve_size(curve); j += clf_curve_size(curve) / 8 + 1) {
        double d = clf_curve_dimension(curve, j);
        printf("  isovalue %8.3f  edges %10llu  D = %s", clf_curve_isovalue(curve, j),
               (unsigned long long)clf_curve_count(curve, 0, j), isnan(d) ? "n/a\n" : "");
        if (!isnan(d)) printf("%.4f\n", d);
    }
    rc = 0;

done:
    clf_curve_destroy(curve);
    clf_volume_destroy(volume);
    clf_context_destroy(ctx);
    return rc;
}
