/* lcp_dump.c — (cli) every LCP a Moreau–Jean run solves, written to HDF5 as
 * a corpus for solver studies (`simulate --dump-lcp F.h5`), and read back
 * (`pound lcp F.h5 --all`).  docs/formats.md and docs/lcp.md describe the
 * layout:
 *
 *   /n, /t, /solver, /outcome, /pivots, /iterations, /residual   one per LCP
 *   /colptr (n_k + 1 per LCP), /rowind, /values                  D_k by columns
 *   /b, /z, /contact                                             n_k per LCP
 *
 * each with its "units"; the provenance (format "pound LCP dump 1"),
 * model, solver_codes and count as root attributes.  Offsets follow from
 * /n and each colptr's last entry.  Datasets are extendible and written in
 * blocks as the run goes; the file is written under a temporary name and
 * renamed when the run has finished.  A failed write stops the run and is
 * reported with the system's reason. */
#include <errno.h>
#include <hdf5.h>
#include <stdlib.h>
#include <string.h>

#include "pd_alloc.h"
#include "pd_h5.h"
#include "pd_lcp_dump.h"
#include "pd_output.h"

#define DUMP_BLOCK (1L << 16) /* entries buffered per dataset */

/* The solvers a dump names, by code. */
static const char *const dump_solvers[] = {"lemke",
                                           "structured",
                                           "pgs",
                                           "lemke (after structured)",
                                           "closed-form",
                                           "structured (after lemke)",
                                           "pgs (after lemke, structured)",
                                           "pgs (after structured, lemke)",
                                           "pgs (after structured)"};
#define NSOLVERS (int)(sizeof dump_solvers / sizeof dump_solvers[0])

/* One extendible dataset with its block buffer. */
typedef struct dump_set {
    const char *name;
    hid_t type;
    size_t size; /* bytes per entry */
    hid_t ds;
    char *buf;
    long nbuf, written;
} dump_set;

enum {
    S_N,
    S_T,
    S_SOLVER,
    S_OUTCOME,
    S_PIVOTS,
    S_ITER,
    S_RES,
    S_COLPTR,
    S_ROWIND,
    S_VALUES,
    S_B,
    S_Z,
    S_CONTACT,
    NSETS
};

struct pd_lcp_dump {
    pd_outfile out;
    hid_t file;
    dump_set set[NSETS];
    long count;
    int failed, failure; /* failure: errno of the first failed write, 0 if none */
};

/* The datasets and their units: a scene's (D = W^T M^-1 W in 1/kg, b a
 * velocity, z an impulse), and the oscillator's, which runs in its Pi
 * units (time wp t, lengths in Le, unit mass): all dimensionless. */
/* Each set's dimension: t (one per LCP, t its coordinate), and three
 * without values: pointer (colptr), nonzero (D's entries) and row (the
 * LCPs' rows). */
static const struct {
    const char *name;
    int is_int;
    const char *units, *dim;
} set_defs[NSETS] = {{"n", 1, "1", "t"},
                     {"t", 0, "s", "t"},
                     {"solver", 1, "1", "t"},
                     {"outcome", 1, "1", "t"},
                     {"pivots", 1, "1", "t"},
                     {"iterations", 1, "1", "t"},
                     {"residual", 0, "1", "t"},
                     {"colptr", 1, "1", "pointer"},
                     {"rowind", 1, "1", "nonzero"},
                     {"values", 0, "1/kg", "nonzero"},
                     {"b", 0, "m/s", "row"},
                     {"z", 0, "N s", "row"},
                     {"contact", 1, "1", "row"}};

/* The dimensions, their lengths the sets' (all written), attached: 0 or -1. */
static int dump_dims(pd_lcp_dump *d)
{
    static const int len_of[] = {S_COLPTR, S_VALUES, S_B}; /* pointer, nonzero, row */
    int rc = pd_h5_coord(d->set[S_T].ds, "t");
    for (int k = 0; k < 3 && !rc; k++) {
        hid_t dim = pd_h5_dimension(d->file, set_defs[len_of[k]].dim, d->set[len_of[k]].written);
        rc = dim < 0 || pd_h5_close_id(&dim);
    }
    for (int k = 0; k < NSETS && !rc; k++)
        rc = k == S_T ? 0 : pd_h5_dims(d->set[k].ds, set_defs[k].dim);
    return rc ? -1 : 0;
}

void pd_lcp_dump_free(pd_lcp_dump *d)
{
    if (!d)
        return;
    for (int k = 0; k < NSETS; k++) {
        pd_h5_close_id(&d->set[k].ds);
        free(d->set[k].buf);
    }
    pd_h5_close(&d->file, &d->failure);
    pd_outfile_abort(&d->out);
    free(d);
}

/* The file and its extendible datasets: 0 or an errno. */
static int dump_create(pd_lcp_dump *d)
{
    pd_provenance p;
    int osc = pd_provenance_tables_are(PD_FORMAT_OSCILLATOR);
    pd_provenance_now(&p, PD_FORMAT_LCP_DUMP);
    if ((d->file = pd_h5_create(d->out.tmp, H5P_DEFAULT, &d->failure)) < 0)
        return d->failure;
    if (pd_provenance_h5(d->file, &p) ||
        pd_h5_attr(d->file, "model", osc ? "oscillator" : "scene", 0.0))
        return d->failure ? d->failure : EIO;
    for (int k = 0; k < NSETS; k++) {
        dump_set *s = &d->set[k];
        if (!(s->buf = malloc(DUMP_BLOCK * s->size)))
            return ENOMEM;
        if ((s->ds = pd_h5_extendible(d->file, s->name, s->type, 0, 4096,
                                      osc ? "1" : set_defs[k].units)) < 0)
            return d->failure ? d->failure : EIO;
    }
    return d->failure;
}

int pd_lcp_dump_open(pd_lcp_dump **out, const char *path, pd_err *err)
{
    pd_lcp_dump *d = calloc(1, sizeof *d);
    int rc, e;
    *out = NULL;
    if (!d)
        return pd_err_set(err, PD_ENOMEM, "--dump-lcp: out of memory");
    d->file = -1;
    d->out.slot = -1;
    for (int k = 0; k < NSETS; k++) {
        dump_set *s = &d->set[k];
        s->name = set_defs[k].name;
        s->type = set_defs[k].is_int ? H5T_NATIVE_INT : H5T_NATIVE_DOUBLE;
        s->size = set_defs[k].is_int ? sizeof(int) : sizeof(double);
        s->ds = -1;
    }
    if (!(rc = pd_outfile_begin(&d->out, "--dump-lcp", path, err)) && (e = dump_create(d)))
        rc = pd_outfile_error(&d->out, e, err);
    if (rc) {
        pd_lcp_dump_free(d);
        return rc;
    }
    *out = d;
    return PD_OK;
}

/* Write a set's buffer. */
static int flush_set(dump_set *s)
{
    if (s->nbuf == 0)
        return 0;
    int rc = pd_h5_append(s->ds, s->type, s->written, s->nbuf, 0, s->buf);
    s->written += s->nbuf;
    s->nbuf = 0;
    return rc;
}

/* Append count entries of a set (ints or doubles as the set holds). */
static int push(dump_set *s, const void *x, long count)
{
    const char *p = x;
    while (count > 0) {
        long room = DUMP_BLOCK - s->nbuf, k = count < room ? count : room;
        memcpy(s->buf + (size_t)s->nbuf * s->size, p, (size_t)k * s->size);
        s->nbuf += k;
        p += (size_t)k * s->size;
        count -= k;
        if (s->nbuf == DUMP_BLOCK && flush_set(s))
            return -1;
    }
    return 0;
}

static int push_int(dump_set *s, int v)
{
    return push(s, &v, 1);
}
static int push_num(dump_set *s, double v)
{
    return push(s, &v, 1);
}

/* The code of a solver name. */
static int solver_code(const char *name)
{
    for (int k = 0; name && k < NSOLVERS; k++)
        if (!strcmp(name, dump_solvers[k]))
            return k;
    return -1;
}

int pd_lcp_dump_add(const pd_matrix *D, const double *b, const double *z, const double *w,
                    const pd_lcp_info *info, const int *idx, double t, void *ctx)
{
    pd_lcp_dump *d = ctx;
    int n = D->rows, nz = 0, rc = 0;
    (void)w;
    if (d->failed)
        return 1;
    dump_set *s = d->set;
    rc |= push_int(&s[S_N], n) || push_num(&s[S_T], t) ||
          push_int(&s[S_SOLVER], solver_code(info->solver)) ||
          push_int(&s[S_OUTCOME], (int)info->outcome) || push_int(&s[S_PIVOTS], info->pivots) ||
          push_int(&s[S_ITER], info->iterations) || push_num(&s[S_RES], info->residual);
    for (int j = 0; j < n && !rc; j++) { /* D by columns, its nonzeros */
        rc |= push_int(&s[S_COLPTR], nz);
        if (D->kind == PD_MATRIX_CSC) {
            for (int k = D->colptr[j]; k < D->colptr[j + 1] && !rc; k++, nz++)
                rc |= push_int(&s[S_ROWIND], D->rowind[k]) || push_num(&s[S_VALUES], D->values[k]);
            continue;
        }
        for (int i = 0; i < n && !rc; i++) {
            double x = D->values[i + (size_t)j * n];
            if (x != 0.0) {
                rc |= push_int(&s[S_ROWIND], i) || push_num(&s[S_VALUES], x);
                nz++;
            }
        }
    }
    rc |= push_int(&s[S_COLPTR], nz) || push(&s[S_B], b, n) || push(&s[S_Z], z, n) ||
          push(&s[S_CONTACT], idx, n);
    d->count++;
    d->failed = rc != 0 || d->failure != 0;
    return d->failed;
}

int pd_lcp_dump_finish(pd_lcp_dump *d, pd_err *err)
{
    int rc = d->failed, e;
    char names[160] = "";
    for (int k = 0; k < NSOLVERS; k++)
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s%d=%s", k ? ", " : "", k,
                 dump_solvers[k]);
    for (int k = 0; k < NSETS && !rc; k++)
        rc = flush_set(&d->set[k]);
    rc = rc || pd_h5_attr(d->file, "solver_codes", names, 0.0) ||
         pd_h5_num(d->file, "count", (double)d->count, "1") || dump_dims(d);
    for (int k = 0; k < NSETS; k++)
        rc |= pd_h5_close_id(&d->set[k].ds);
    e = pd_h5_close(&d->file, &d->failure);
    if (e || rc) {
        pd_outfile_abort(&d->out);
        return pd_outfile_error(&d->out, e ? e : EIO, err);
    }
    return pd_outfile_commit(&d->out, err);
}

long pd_lcp_dump_count(const pd_lcp_dump *d)
{
    return d->count;
}

/* ---- reading ------------------------------------------------------------------ */

void pd_lcp_set_free(pd_lcp_set *s)
{
    free(s->n);
    free(s->t);
    free(s->solver);
    free(s->outcome);
    free(s->iterations);
    free(s->pivots);
    free(s->colptr);
    free(s->rowind);
    free(s->values);
    free(s->b);
    free(s->z);
    free(s->voff);
    free(s->poff);
    free(s->eoff);
    memset(s, 0, sizeof *s);
}

/* A whole 1-D dataset into a malloc'd array; its length in *len. */
static void *read_all(hid_t file, const char *name, hid_t type, size_t size, long *len)
{
    hid_t ds = H5Dopen2(file, name, H5P_DEFAULT);
    void *buf = NULL;
    *len = -1;
    if (ds < 0)
        return NULL;
    hid_t sp = H5Dget_space(ds);
    hsize_t dims[1] = {0};
    if (sp >= 0 && H5Sget_simple_extent_ndims(sp) == 1 &&
        H5Sget_simple_extent_dims(sp, dims, NULL) == 1) {
        buf = pd_malloc((long)dims[0], size);
        if (buf && (dims[0] == 0 || H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) >= 0))
            *len = (long)dims[0];
        else {
            free(buf);
            buf = NULL;
        }
    }
    if (sp >= 0)
        H5Sclose(sp);
    H5Dclose(ds);
    return buf;
}

int pd_lcp_set_read(const char *path, pd_lcp_set *s, pd_err *err)
{
    long len[11];
    memset(s, 0, sizeof *s);
    pd_h5_start();
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (f < 0)
        return pd_err_set(err, PD_EIO, "%s: cannot open as HDF5", path);
    s->n = read_all(f, "n", H5T_NATIVE_INT, sizeof(int), &len[0]);
    s->t = read_all(f, "t", H5T_NATIVE_DOUBLE, sizeof(double), &len[1]);
    s->solver = read_all(f, "solver", H5T_NATIVE_INT, sizeof(int), &len[2]);
    s->outcome = read_all(f, "outcome", H5T_NATIVE_INT, sizeof(int), &len[3]);
    s->iterations = read_all(f, "iterations", H5T_NATIVE_INT, sizeof(int), &len[4]);
    s->pivots = read_all(f, "pivots", H5T_NATIVE_INT, sizeof(int), &len[5]);
    s->colptr = read_all(f, "colptr", H5T_NATIVE_INT, sizeof(int), &len[6]);
    s->rowind = read_all(f, "rowind", H5T_NATIVE_INT, sizeof(int), &len[7]);
    s->values = read_all(f, "values", H5T_NATIVE_DOUBLE, sizeof(double), &len[8]);
    s->b = read_all(f, "b", H5T_NATIVE_DOUBLE, sizeof(double), &len[9]);
    s->z = read_all(f, "z", H5T_NATIVE_DOUBLE, sizeof(double), &len[10]);
    H5Fclose(f);
    for (int k = 0; k < 11; k++)
        if (len[k] < 0) {
            pd_lcp_set_free(s);
            return pd_err_set(err, PD_EPARSE, "%s: not a pound LCP dump (a dataset is missing)",
                              path);
        }
    s->count = len[0];
    s->voff = malloc((size_t)(s->count + 1) * sizeof(long));
    s->poff = malloc((size_t)(s->count + 1) * sizeof(long));
    s->eoff = malloc((size_t)(s->count + 1) * sizeof(long));
    if (!s->voff || !s->poff || !s->eoff) {
        pd_lcp_set_free(s);
        return pd_err_set(err, PD_ENOMEM, "%s: out of memory", path);
    }
    s->voff[0] = s->poff[0] = s->eoff[0] = 0;
    int bad = len[1] != s->count || len[2] != s->count || len[3] != s->count ||
              len[4] != s->count || len[5] != s->count;
    for (long k = 0; k < s->count && !bad; k++) {
        int n = s->n[k];
        bad = n < 1 || s->poff[k] + n + 1 > len[6];
        if (bad)
            break;
        const int *cp = s->colptr + s->poff[k];
        s->voff[k + 1] = s->voff[k] + n;
        s->poff[k + 1] = s->poff[k] + n + 1;
        s->eoff[k + 1] = s->eoff[k] + cp[n];
        s->nmax = n > s->nmax ? n : s->nmax;
        s->nnzmax = cp[n] > s->nnzmax ? cp[n] : s->nnzmax;
        bad = cp[0] != 0 || s->eoff[k + 1] > len[7] || s->voff[k + 1] > len[9];
        for (int j = 0; j < n && !bad; j++)
            bad = cp[j + 1] < cp[j];
        for (long e = s->eoff[k]; e < s->eoff[k + 1] && !bad; e++)
            bad = s->rowind[e] < 0 || s->rowind[e] >= n;
    }
    if (bad || len[7] != len[8] || len[9] != len[10]) {
        pd_lcp_set_free(s);
        return pd_err_set(err, PD_EPARSE, "%s: the LCP dump is inconsistent", path);
    }
    return PD_OK;
}

pd_matrix pd_lcp_set_matrix(const pd_lcp_set *s, long k)
{
    return pd_matrix_csc(s->n[k], s->n[k], s->colptr + s->poff[k], s->rowind + s->eoff[k],
                         s->values + s->eoff[k]);
}

const char *pd_lcp_set_solver_name(int code)
{
    return code >= 0 && code < NSOLVERS ? dump_solvers[code] : "?";
}
