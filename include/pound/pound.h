/* pound.h — the public API of libpound: nonsmooth dynamics of pounding
 * structures (docs/api.md).
 *
 *     #include <pound/pound.h>
 *     cc prog.c $(pkg-config --cflags --libs pound)
 *
 * The four module headers, each usable alone, in layer order:
 *   pd_core.h      status codes and messages (pd_err), version, matrices
 *                  (dense and compressed columns), sparse assembly, dense LU
 *   pd_lcp.h       linear complementarity problems: Lemke, structured, PGS
 *                  behind one solver table; LCP files
 *   pd_engine.h    linear systems with unilateral contacts: Moreau-Jean,
 *                  the event-driven references, the penalty baseline
 *   pd_problems.h  excitations and strong-motion records, the pounding
 *                  oscillator in Pi terms, scenes (rows of structures), the
 *                  run request, measurements, spectrum and scene sweeps
 *
 * Every function that can fail returns 0 (PD_OK) or a negative PD_E* status
 * and fills a pd_err (which may be NULL) with one line; the library never
 * prints, exits or aborts.  Compare PD_VERSION (compiled against) with
 * pd_version() (linked) to detect a mismatch. */
#ifndef POUND_H
#define POUND_H

#include <stddef.h> /* the system headers the modules include, outside extern "C" */
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

#include "pd_core.h"
#include "pd_lcp.h"
#include "pd_engine.h"
#include "pd_problems.h"

#ifdef __cplusplus
}
#endif

#endif
