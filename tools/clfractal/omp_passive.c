/* libclfractal_omp_passive: OMP_WAIT_POLICY=passive for the command-line tools, unless the
 * user chose a policy (OMP_WAIT_POLICY or GOMP_SPINCOUNT).
 *
 * OpenMP's threads spin for a while after each parallel region (libgomp's default: about
 * 300,000 turns, milliseconds); on a CPU device they take the cores from the OpenCL runtime's
 * own worker threads, which run the kernels next (PoCL runs them on the same cores), and the
 * library's parallel regions are coarse enough that a passive wait costs nothing.
 *
 * libgomp reads its environment once, in its own initialiser, so the variable must be set
 * before that runs. An executable's .preinit_array is too early: the C library sets the
 * environment up after it, dropping what was set there. The initialisers of a program's
 * libraries run after the C library's and before the program's, in the reverse order of its
 * DT_NEEDED list (each after the libraries it needs), so this library is linked after
 * libgomp (CMakeLists.txt) and has an initialiser of its own. The cli test checks that
 * libgomp sees the policy (OMP_DISPLAY_ENV=verbose: GOMP_SPINCOUNT '0').
 */
#include <stdlib.h>

__attribute__((constructor)) static void clfractal_passive_openmp(void) {
    if (!getenv("OMP_WAIT_POLICY") && !getenv("GOMP_SPINCOUNT")) setenv("OMP_WAIT_POLICY", "passive", 0);
}
