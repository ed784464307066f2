// Functions compiled twice on x86-64, for an instruction set extension beyond the baseline and
// for the baseline, the copy chosen at load time (GCC's and Clang's target_clones). Private
// to the library.
//
// CLFRACTAL_CLONES("ext") where clones may be made, else nothing. ThreadSanitizer builds go
// without: the loader runs the choosing function (an ifunc resolver) before the TSan runtime
// starts, and its instrumented entry then crashes.
#pragma once

#if defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define CLFRACTAL_TSAN 1
#endif
#endif
#if defined(__SANITIZE_THREAD__)
#define CLFRACTAL_TSAN 1
#endif

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(CLFRACTAL_TSAN)
#define CLFRACTAL_CLONES(ext) __attribute__((target_clones(ext, "default")))
#else
#define CLFRACTAL_CLONES(ext)
#endif
