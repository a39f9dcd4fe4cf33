/* suite_journal.c — a suite's finished records as journal lines (--journal
 * F, --resume; and the lines MPI ranks send rank 0):
 *
 *   pound-suite-journal 1
 *   key <the suite's flags, its records, pound's version and layouts>
 *   R <k> O <the bytes of pd_osc_summary in hex> <r.kernel> <free.kernel> #<fnv1a>
 *   R <k> S <every field of pd_scene_summary, in the tables' order> #<fnv1a>
 *
 * The oscillator's summary is flat but for its kernel names: its bytes go
 * as they are (the key holds the struct's size and pound's version, so a
 * journal is read back by the build that wrote it).  A scene's summary
 * holds arrays: the tables below list every field, doubles in C99
 * hexadecimal, so that a resumed suite prints the figures to the bit.
 * Names are written "=name" (bytes outside printing ASCII, '%' and '#' as
 * %XX), NULL as "-". */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_alloc.h"
#include "pd_journal.h"

static const pd_journal_kind suite_journal = {
    .magic = "pound-suite-journal 1\n", .flag = "--journal", .what = "suite", .run = "suite"};

int pd_suite_journal_open(pd_journal *j, const char *path, const char *key, int resume,
                          pd_journal_reader read, void *ctx, pd_err *err)
{
    return pd_journal_open(j, &suite_journal, path, key, resume, read, ctx, err);
}

void pd_suite_names_free(pd_suite_names *p)
{
    for (int i = 0; i < p->n; i++)
        free(p->s[i]);
    free(p->s);
    *p = (pd_suite_names){.n = 0};
}

/* ---- the fields of a scene's summary ------------------------------------- */

typedef enum { F_INT, F_LONG, F_DOUBLE, F_NAME, F_DOUBLES, F_LONGS } field_kind;
typedef enum { C_ONE, C_DOF, C_CONTACT, C_STRUCT } field_count;
typedef struct field {
    field_kind kind;
    field_count count;
    size_t offset;
} field;

#define R_(k, c, f)                                                                                \
    {                                                                                              \
        .kind = k, .count = c, .offset = offsetof(pd_scene_result, f)                              \
    }
#define S_(k, c, f)                                                                                \
    {                                                                                              \
        .kind = k, .count = c, .offset = offsetof(pd_scene_summary, f)                             \
    }

/* pd_scene_result but n, m and nstruct (pd_scene_result_alloc's). */
static const field result_fields[] = {R_(F_LONG, C_ONE, steps),
                                      R_(F_LONG, C_ONE, lcp_solves),
                                      R_(F_LONG, C_ONE, simultaneous),
                                      R_(F_LONG, C_ONE, tol_closed),
                                      R_(F_LONG, C_ONE, accumulations),
                                      R_(F_LONG, C_ONE, steps_rejected),
                                      R_(F_LONG, C_ONE, law_decided),
                                      R_(F_DOUBLE, C_ONE, close_tol),
                                      R_(F_DOUBLE, C_ONE, dt),
                                      R_(F_DOUBLE, C_ONE, tend),
                                      R_(F_DOUBLE, C_ONE, theta),
                                      R_(F_DOUBLE, C_ONE, cpu_s),
                                      R_(F_DOUBLE, C_ONE, contact_duration),
                                      R_(F_DOUBLE, C_ONE, rtol),
                                      R_(F_DOUBLE, C_ONE, err_est_max),
                                      R_(F_DOUBLE, C_ONE, dt_min),
                                      R_(F_DOUBLE, C_ONE, dt_max),
                                      R_(F_DOUBLE, C_ONE, law_band_max),
                                      R_(F_DOUBLE, C_ONE, energy.input),
                                      R_(F_DOUBLE, C_ONE, energy.kinetic),
                                      R_(F_DOUBLE, C_ONE, energy.strain),
                                      R_(F_DOUBLE, C_ONE, energy.damping),
                                      R_(F_DOUBLE, C_ONE, energy.hysteretic),
                                      R_(F_DOUBLE, C_ONE, energy.impact),
                                      R_(F_DOUBLE, C_ONE, energy.residual),
                                      R_(F_INT, C_ONE, rtol_met),
                                      R_(F_NAME, C_ONE, method),
                                      R_(F_NAME, C_ONE, kernel),
                                      R_(F_NAME, C_ONE, factor),
                                      R_(F_NAME, C_ONE, lcp_solver),
                                      R_(F_NAME, C_ONE, impact_law),
                                      R_(F_DOUBLES, C_DOF, umax),
                                      R_(F_DOUBLES, C_DOF, u_pos),
                                      R_(F_DOUBLES, C_DOF, u_neg),
                                      R_(F_DOUBLES, C_DOF, drift),
                                      R_(F_DOUBLES, C_DOF, acc_max),
                                      R_(F_DOUBLES, C_DOF, shear_max),
                                      R_(F_DOUBLES, C_DOF, drift_ratio),
                                      R_(F_DOUBLES, C_DOF, ductility),
                                      R_(F_DOUBLES, C_DOF, residual),
                                      R_(F_DOUBLES, C_DOF, plastic_excursion),
                                      R_(F_LONGS, C_DOF, n_yield),
                                      R_(F_LONGS, C_CONTACT, impacts),
                                      R_(F_DOUBLES, C_CONTACT, first_impact),
                                      R_(F_DOUBLES, C_CONTACT, max_impulse),
                                      R_(F_DOUBLES, C_CONTACT, contact_time),
                                      R_(F_DOUBLES, C_CONTACT, approach),
                                      R_(F_DOUBLES, C_CONTACT, force_max),
                                      R_(F_DOUBLES, C_CONTACT, force_equiv),
                                      R_(F_DOUBLES, C_STRUCT, err_est),
                                      R_(F_DOUBLES, C_STRUCT, law_band)};

/* pd_scene_summary but its two results. */
static const field summary_fields[] = {S_(F_DOUBLE, C_ONE, cpu_s),
                                       S_(F_DOUBLE, C_ONE, err_est),
                                       S_(F_INT, C_ONE, rtol_met),
                                       S_(F_DOUBLES, C_DOF, Pi1),
                                       S_(F_DOUBLES, C_DOF, gamma),
                                       S_(F_DOUBLES, C_STRUCT, Pi2),
                                       S_(F_DOUBLES, C_STRUCT, err_est_structure),
                                       S_(F_DOUBLES, C_CONTACT, Pi3),
                                       S_(F_DOUBLES, C_CONTACT, chi),
                                       S_(F_DOUBLES, C_CONTACT, required_gap),
                                       S_(F_DOUBLES, C_CONTACT, rule_abs),
                                       S_(F_DOUBLES, C_CONTACT, rule_srss),
                                       S_(F_DOUBLES, C_CONTACT, rule_ddc)};

#undef R_
#undef S_

enum {
    NRESULT = sizeof result_fields / sizeof *result_fields,
    NSUMMARY = sizeof summary_fields / sizeof *summary_fields
};

/* The count of a field's values in a scene of n dofs, m contacts, ns
 * structures. */
static long field_len(const field *f, int n, int m, int ns)
{
    return f->count == C_DOF ? n : f->count == C_CONTACT ? m : f->count == C_STRUCT ? ns : 1;
}

/* ---- writing ------------------------------------------------------------- */

/* A name as its token ("=name" escaped, "-" for NULL). */
static void put_name(FILE *f, const char *s)
{
    if (!s) {
        fputs(" -", f);
        return;
    }
    fputs(" =", f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c <= ' ' || c >= 0x7f || c == '%' || c == '#')
            fprintf(f, "%%%02X", c);
        else
            fputc(c, f);
    }
}

/* The fields of one struct at base (n dofs, m contacts, ns structures). */
static void put_fields(FILE *f, const field *fs, int nf, const void *base, int n, int m, int ns)
{
    for (int i = 0; i < nf; i++) {
        const char *p = (const char *)base + fs[i].offset;
        long len = field_len(&fs[i], n, m, ns);
        switch (fs[i].kind) {
        case F_INT:
            fprintf(f, " %d", *(const int *)p);
            break;
        case F_LONG:
            fprintf(f, " %ld", *(const long *)p);
            break;
        case F_DOUBLE:
            fprintf(f, " %a", *(const double *)p);
            break;
        case F_NAME:
            put_name(f, *(const char *const *)p);
            break;
        case F_DOUBLES:
            for (long k = 0; k < len; k++)
                fprintf(f, " %a", (*(double *const *)p)[k]);
            break;
        case F_LONGS:
            for (long k = 0; k < len; k++)
                fprintf(f, " %ld", (*(long *const *)p)[k]);
            break;
        }
    }
}

/* What f wrote, closed: the body, or NULL when a write failed. */
static char *close_body(FILE *f, char **buf)
{
    int bad = ferror(f);
    if (fclose(f) || bad) {
        free(*buf);
        return NULL;
    }
    return *buf;
}

char *pd_suite_osc_body(int k, const pd_osc_summary *s, size_t *len)
{
    char *buf = NULL;
    FILE *f = open_memstream(&buf, len);
    if (!f)
        return NULL;
    pd_osc_summary v = *s; /* its names go as names, not as addresses */
    v.r.kernel = v.free.kernel = NULL;
    const unsigned char *b = (const unsigned char *)&v;
    fprintf(f, "R %d O ", k);
    for (size_t i = 0; i < sizeof v; i++)
        fprintf(f, "%02x", b[i]);
    put_name(f, s->r.kernel);
    put_name(f, s->free.kernel);
    return close_body(f, &buf);
}

char *pd_suite_scene_body(int k, const pd_scene_summary *s, size_t *len)
{
    char *buf = NULL;
    FILE *f = open_memstream(&buf, len);
    if (!f)
        return NULL;
    int n = s->r.n, m = s->r.m, ns = s->r.nstruct;
    fprintf(f, "R %d S %d %d %d", k, n, m, ns);
    put_fields(f, result_fields, NRESULT, &s->r, n, m, ns);
    put_fields(f, result_fields, NRESULT, &s->free, n, m, ns);
    put_fields(f, summary_fields, NSUMMARY, s, n, m, ns);
    return close_body(f, &buf);
}

/* ---- reading ------------------------------------------------------------- */

/* The tokens of a body: a copy split at its blanks. */
typedef struct tokens {
    char *copy, *save;
    int started;
} tokens;

static const char *tok(tokens *t)
{
    const char *s = strtok_r(t->started ? NULL : t->copy, " ", &t->save);
    t->started = 1;
    return s;
}

static int tok_long(tokens *t, long *v)
{
    const char *s = tok(t);
    char *end;
    if (!s)
        return -1;
    *v = strtol(s, &end, 10);
    return *end ? -1 : 0;
}

static int tok_double(tokens *t, double *v)
{
    const char *s = tok(t);
    char *end;
    if (!s)
        return -1;
    *v = strtod(s, &end);
    return *end ? -1 : 0;
}

/* A hexadecimal digit's value, or -1. */
static int hex_digit(char c)
{
    return c >= '0' && c <= '9'   ? c - '0'
           : c >= 'A' && c <= 'F' ? c - 'A' + 10
           : c >= 'a' && c <= 'f' ? c - 'a' + 10
                                  : -1;
}

/* A name token back: NULL for "-", else the name kept in names (one copy
 * of each). */
static int tok_name(tokens *t, pd_suite_names *names, const char **out)
{
    const char *s = tok(t);
    if (!s || (strcmp(s, "-") && s[0] != '='))
        return -1;
    if (!strcmp(s, "-")) {
        *out = NULL;
        return 0;
    }
    char *name = malloc(strlen(s)), *o = name;
    if (!name)
        return -1;
    for (s++; *s; s++) { /* %XX: exactly two hex digits, not NUL */
        if (*s != '%') {
            *o++ = *s;
            continue;
        }
        int hi = hex_digit(s[1]), lo = hi < 0 ? -1 : hex_digit(s[2]);
        if (lo < 0 || (hi | lo) == 0) {
            free(name);
            return -1;
        }
        *o++ = (char)(16 * hi + lo);
        s += 2;
    }
    *o = '\0';
    for (int i = 0; i < names->n; i++)
        if (!strcmp(names->s[i], name)) {
            free(name);
            *out = names->s[i];
            return 0;
        }
    if (names->n == names->cap) {
        int cap = names->cap ? 2 * names->cap : 8;
        char **grown = realloc(names->s, (size_t)cap * sizeof *grown);
        if (!grown) {
            free(name);
            return -1;
        }
        names->s = grown;
        names->cap = cap;
    }
    *out = names->s[names->n++] = name;
    return 0;
}

/* The head "R <k> <form>": 0, or -1 when it is not one of n records. */
static int tok_head(tokens *t, const char *body, size_t len, int n, const char *form, int *k)
{
    long kk;
    *t = (tokens){.copy = malloc(len + 1)};
    if (!t->copy || memchr(body, '\0', len)) /* a NUL would end the tokens early */
        return -1;
    memcpy(t->copy, body, len);
    t->copy[len] = '\0';
    const char *r = tok(t);
    if (!r || strcmp(r, "R") || tok_long(t, &kk) || kk < 0 || kk >= n)
        return -1;
    const char *f = tok(t);
    *k = (int)kk;
    return f && !strcmp(f, form) ? 0 : -1;
}

int pd_suite_osc_parse(const char *body, size_t len, int n, int *k, pd_osc_summary *s,
                       pd_suite_names *names)
{
    tokens t;
    int rc = tok_head(&t, body, len, n, "O", k);
    const char *hex = rc ? NULL : tok(&t);
    pd_osc_summary v;
    unsigned char *b = (unsigned char *)&v;
    if (!hex || strlen(hex) != 2 * sizeof v)
        rc = -1;
    for (size_t i = 0; !rc && i < sizeof v; i++) {
        unsigned int c;
        if (sscanf(hex + 2 * i, "%2x", &c) != 1)
            rc = -1;
        b[i] = (unsigned char)c;
    }
    if (!rc && !tok_name(&t, names, &v.r.kernel) && !tok_name(&t, names, &v.free.kernel) &&
        !tok(&t))
        *s = v;
    else
        rc = -1;
    free(t.copy);
    return rc;
}

/* The fields of one struct at base back from t. */
static int get_fields(tokens *t, const field *fs, int nf, void *base, int n, int m, int ns,
                      pd_suite_names *names)
{
    for (int i = 0; i < nf; i++) {
        char *p = (char *)base + fs[i].offset;
        long len = field_len(&fs[i], n, m, ns), v;
        int rc = 0;
        switch (fs[i].kind) {
        case F_INT:
            rc = tok_long(t, &v);
            *(int *)p = (int)v;
            break;
        case F_LONG:
            rc = tok_long(t, (long *)p);
            break;
        case F_DOUBLE:
            rc = tok_double(t, (double *)p);
            break;
        case F_NAME:
            rc = tok_name(t, names, (const char **)p);
            break;
        case F_DOUBLES:
            for (long k = 0; k < len && !rc; k++)
                rc = tok_double(t, &(*(double **)p)[k]);
            break;
        case F_LONGS:
            for (long k = 0; k < len && !rc; k++)
                rc = tok_long(t, &(*(long **)p)[k]);
            break;
        }
        if (rc)
            return -1;
    }
    return 0;
}

/* The summary's own arrays for sc: 0 or -1. */
static int summary_alloc(const pd_scene *sc, pd_scene_summary *s)
{
    pd_err err;
    if (pd_scene_result_alloc(sc, &s->r, &err) || pd_scene_result_alloc(sc, &s->free, &err))
        return -1;
    for (int i = 0; i < NSUMMARY; i++) {
        if (summary_fields[i].kind != F_DOUBLES)
            continue;
        double **p = (double **)((char *)s + summary_fields[i].offset);
        long len = field_len(&summary_fields[i], sc->n, sc->ncontact, sc->nstruct);
        if (!(*p = pd_calloc(len > 0 ? len : 1, sizeof **p)))
            return -1;
    }
    return 0;
}

int pd_suite_scene_parse(const char *body, size_t len, const pd_scene *sc, int n, int *k,
                         pd_scene_summary *s, pd_suite_names *names)
{
    tokens t;
    long dims[3];
    int ndof = sc->n, m = sc->ncontact, ns = sc->nstruct;
    memset(s, 0, sizeof *s);
    int rc = tok_head(&t, body, len, n, "S", k);
    for (int i = 0; i < 3 && !rc; i++)
        rc = tok_long(&t, &dims[i]);
    if (!rc && (dims[0] != ndof || dims[1] != m || dims[2] != ns))
        rc = -1;
    if (!rc)
        rc = summary_alloc(sc, s);
    if (!rc)
        rc = get_fields(&t, result_fields, NRESULT, &s->r, ndof, m, ns, names) ||
                     get_fields(&t, result_fields, NRESULT, &s->free, ndof, m, ns, names) ||
                     get_fields(&t, summary_fields, NSUMMARY, s, ndof, m, ns, names) || tok(&t)
                 ? -1
                 : 0;
    free(t.copy);
    if (rc)
        pd_scene_summary_free(s);
    return rc;
}
