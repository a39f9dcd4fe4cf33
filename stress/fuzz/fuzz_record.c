/* fuzz_record.c — libFuzzer harness of the strong-motion record readers
 * (pd_record_read, problems/record.c): every input is read as auto, AT2, V2
 * and text.  A record that reads must have npts >= 2, dt > 0 and finite
 * samples (docs/records.md); a short one is also measured and its pulse
 * fitted (GSL, whose error handler the fit turns off). */
#include <math.h>

#include "fuzz_common.h"
#include "pd_problems.h"

static void check(const char *path, pd_record_format format, pd_record_units units)
{
    pd_record rec;
    pd_err err;
    memset(&rec, 0, sizeof rec);
    memset(&err, 0, sizeof err);
    if (pd_record_read(path, format, units, &rec, &err) != PD_OK) {
        if (rec.acc || rec.npts)
            abort(); /* "on error rec is left empty" */
        if (!err.msg[0] || strchr(err.msg, '\n'))
            abort(); /* one non-empty line */
        return;
    }
    if (rec.npts < 2 || !(rec.dt > 0.0) || !isfinite(rec.dt) || !rec.acc)
        abort();
    for (long i = 0; i < rec.npts; i++)
        if (!isfinite(rec.acc[i]))
            abort();
    if (rec.npts <= 2048) {
        pd_record_measures m;
        pd_record_pulse p;
        if (pd_record_measure(&rec, &m, &err) == PD_OK)
            (void)pd_record_fit_pulse(&rec, &p, &err);
    }
    pd_record_free(&rec);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[1024];
    fuzz_write("in.AT2", data, size, path, sizeof path);
    check(path, PD_RECORD_AUTO, PD_UNITS_G);
    check(path, PD_RECORD_AT2, PD_UNITS_G);
    check(path, PD_RECORD_V2, PD_UNITS_G);
    check(path, PD_RECORD_TEXT, PD_UNITS_CM_S2);
    return 0;
}
