/* clf_analyse VOLUME: the C ABI's analysis of a volume as JSON on stdout, with the options
 * `clfractal fd` uses by default (components at the recommended isovalues, no noise level,
 * the denoising ladder when nothing is clean). Written in C, so that the test also proves
 * clfractal.h is a C header. Exit 2 with the library's message on failure. */
#include <stdio.h>

#include "clfractal/clfractal.h"

int main(int argc, char** argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: clf_analyse VOLUME\n");
        return 2;
    }
    clf_context* ctx = NULL;
    clf_volume* volume = NULL;
    clf_analysis* analysis = NULL;
    clf_analysis_options options;
    clf_analysis_options_default(&options);
    options.noise_level = 0;
    int rc = 2;
    if (clf_context_create(NULL, &ctx) == CLF_OK && clf_volume_read(argv[1], &volume) == CLF_OK &&
        clf_analyse(ctx, volume, &options, &analysis) == CLF_OK) {
        fputs(clf_analysis_json(analysis), stdout);
        fputs("\n", stdout);
        rc = 0;
    } else {
        fprintf(stderr, "clf_analyse: %s\n", clf_last_error());
    }
    clf_analysis_destroy(analysis);
    clf_volume_destroy(volume);
    clf_context_destroy(ctx);
    return rc;
}
