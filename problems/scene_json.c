/* scene_json.c — reading a scene file (JSON, docs/scenes.md) with jansson.
 *
 * jansson parses (syntax errors come with its line and column, duplicate
 * keys and trailing text are refused); the tree is then checked field by
 * field.  Every error names FILE:LINE:COL and the field path, e.g.
 *   scene.json:14:9: structures[1].storeys: expected a positive integer
 * jansson keeps no positions for values, so the position of a field is
 * found again in the text by walking the path (the text is valid JSON by
 * then). */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "pd_null.h"
#include "pd_problems.h"
#include "pd_core.h"

#define SCENE_FILE_MAX (256L << 20) /* largest scene file read, bytes */

/* The usable ranges of a scene's values.  Structures that pound have
 * periods of 0.1 to 10 s, pulses 0.1 to 5 s, storeys 10^4 to 10^7 kg and
 * 10^6 to 10^10 N/m, gaps of centimetres; the ranges are wider by decades,
 * and narrow enough that what is derived from them stays far inside the
 * doubles: w0 = 2 pi / T0, w0^2, the stiffness m w0^2 and the ratios
 * k / m, C = alpha M + beta K, Le = ap / wp^2 and gap / Le.  The shortest
 * period also sets the run's cost: the default step is min(Tp, T0) / 2000,
 * so a period of 0.01 s makes it 5 us, 2 10^5 steps a second of motion (a
 * 1 kg storey on 6e8 N/m, T0 = 0.6 ms, asked for 10^7 steps and a hang). */
#define SCENE_PERIOD_MIN 1e-2 /* s: T0, a building's fundamental period, Tp */
#define SCENE_PERIOD_MAX 1e3
#define SCENE_MASS_MIN 1e-6 /* kg, of a storey */
#define SCENE_MASS_MAX 1e12
#define SCENE_STIFF_MIN 1e-11 /* N/m: m w0^2 over the mass and period ranges */
#define SCENE_STIFF_MAX 1e18
#define SCENE_AP_MIN 1e-6    /* m/s^2 (also a record's fitted ap times its scale) */
#define SCENE_AP_MAX 1e4     /* about 1000 g */
#define SCENE_SCALE_MIN 1e-6 /* a record's scale */
#define SCENE_SCALE_MAX 1e6
#define SCENE_GAP_MAX 1e3       /* m */
#define SCENE_TEND_MAX 1e5      /* s, about a day of motion */
#define SCENE_LEVELS_MAX 100000 /* entries of one levels or pairs list */

/* The file being read. */
typedef struct loader {
    const char *path;
    char *text;
    size_t len;
    pd_err *err;
} loader;

/* ---- positions ------------------------------------------------------------- */

static size_t skip_ws(const char *t, size_t p)
{
    while (t[p] == ' ' || t[p] == '\t' || t[p] == '\n' || t[p] == '\r')
        p++;
    return p;
}

/* Past a string starting at its opening quote. */
static size_t skip_string(const char *t, size_t p)
{
    for (p++; t[p] && t[p] != '"'; p++)
        if (t[p] == '\\' && t[p + 1])
            p++;
    return t[p] ? p + 1 : p;
}

/* Past any value (the text is valid JSON). */
static size_t skip_value(const char *t, size_t p)
{
    p = skip_ws(t, p);
    if (t[p] == '"')
        return skip_string(t, p);
    if (t[p] == '{' || t[p] == '[') {
        int depth = 0;
        for (; t[p]; p++) {
            if (t[p] == '"') {
                p = skip_string(t, p) - 1;
                continue;
            }
            depth += (t[p] == '{' || t[p] == '[') - (t[p] == '}' || t[p] == ']');
            if (depth == 0)
                return p + 1;
        }
        return p;
    }
    while (t[p] && !strchr(",]} \t\r\n", t[p]))
        p++;
    return p;
}

/* Does the string at p (its opening quote) equal key? */
static int key_is(const char *t, size_t p, const char *key, size_t klen)
{
    return t[p] == '"' && !strncmp(t + p + 1, key, klen) && t[p + 1 + klen] == '"';
}

/* The value of member key in the object at p, or (size_t)-1. */
static size_t member_at(const char *t, size_t p, const char *key, size_t klen)
{
    p = skip_ws(t, p);
    if (t[p] != '{')
        return (size_t)-1;
    p = skip_ws(t, p + 1);
    while (t[p] == '"') {
        int hit = key_is(t, p, key, klen);
        p = skip_ws(t, skip_string(t, p));
        p = skip_ws(t, p + 1); /* past ':' */
        if (hit)
            return p;
        p = skip_ws(t, skip_value(t, p));
        if (t[p] == ',')
            p = skip_ws(t, p + 1);
    }
    return (size_t)-1;
}

/* Element k of the array at p, or (size_t)-1. */
static size_t element_at(const char *t, size_t p, long k)
{
    p = skip_ws(t, p);
    if (t[p] != '[')
        return (size_t)-1;
    p = skip_ws(t, p + 1);
    for (long i = 0; t[p] && t[p] != ']'; i++) {
        if (i == k)
            return p;
        p = skip_ws(t, skip_value(t, p));
        if (t[p] == ',')
            p = skip_ws(t, p + 1);
    }
    return (size_t)-1;
}

/* Offset of the value at path ("structures[1].storeys"), or of the
 * deepest part of it that exists. */
static size_t locate(const char *t, const char *path)
{
    size_t p = skip_ws(t, 0), q;
    const char *s = path;
    while (*s) {
        if (*s == '[') {
            long k = strtol(s + 1, (char **)&s, 10);
            q = element_at(t, p, k);
            s += *s == ']';
        } else {
            size_t klen = strcspn(s, ".[");
            q = member_at(t, p, s, klen);
            s += klen;
        }
        if (q == (size_t)-1)
            break;
        p = q;
        s += *s == '.';
    }
    return p;
}

/* Line and column (1-based) of an offset. */
static void line_col(const char *t, size_t off, int *line, int *col)
{
    *line = 1;
    size_t start = 0;
    for (size_t i = 0; i < off && t[i]; i++)
        if (t[i] == '\n') {
            (*line)++;
            start = i + 1;
        }
    *col = (int)(off - start) + 1;
}

/* A copy of s fit for a one-line message: control bytes become '?'. */
static const char *printable(const char *s, char *buf, size_t cap)
{
    size_t k = 0;
    for (; s && *s && k + 1 < cap; s++)
        buf[k++] = (unsigned char)*s < 0x20 || *s == 0x7f ? '?' : *s;
    buf[k] = '\0';
    return buf;
}

/* "FILE:LINE:COL: field: message" for the field at path. */
static int fail(loader *L, const char *path, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static int fail(loader *L, const char *path, const char *fmt, ...)
{
    char msg[200];
    int line, col;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    line_col(L->text, locate(L->text, path), &line, &col);
    return pd_err_set(L->err, PD_EPARSE, "%s:%d:%d: %s%s%s", L->path, line, col, path,
                      path[0] ? ": " : "", msg);
}

/* A builder's message "field: text" reported at path.field. */
static int fail_builder(loader *L, const char *path, const pd_err *e)
{
    char sub[160];
    const char *colon = strstr(e->msg, ": ");
    if (!colon || (size_t)(colon - e->msg) >= 40)
        return fail(L, path, "%s", e->msg);
    snprintf(sub, sizeof sub, "%s.%.*s", path, (int)(colon - e->msg), e->msg);
    return fail(L, strchr(sub, '.') == sub ? sub + 1 : sub, "%s", colon + 2);
}

/* ---- fields ------------------------------------------------------------------ */

/* Only the named keys in object obj at path. */
static int only_keys(loader *L, json_t *obj, const char *path, const char *const *keys)
{
    const char *k;
    json_t *v;
    char at[160], name[64];
    json_object_foreach(obj, k, v)
    {
        int known = 0;
        for (const char *const *q = keys; *q && !known; q++)
            known = !strcmp(k, *q);
        if (!known) {
            snprintf(at, sizeof at, "%s%s%s", path, path[0] ? "." : "", k);
            return fail(L, at, "unknown field '%s'", printable(k, name, sizeof name));
        }
    }
    return PD_OK;
}

/* Path of a member. */
static const char *field(char *buf, size_t cap, const char *path, const char *key)
{
    snprintf(buf, cap, "%s%s%s", path, path[0] ? "." : "", key);
    return buf;
}

/* A finite number field; required or with a default. */
static int get_number(loader *L, json_t *obj, const char *path, const char *key, int required,
                      double def, double *out)
{
    char at[160];
    json_t *v = json_object_get(obj, key);
    if (!v) {
        if (required)
            return fail(L, path, "missing field '%s' (a number)", key);
        *out = def;
        return PD_OK;
    }
    if (!json_is_number(v))
        return fail(L, field(at, sizeof at, path, key), "expected a number");
    *out = json_number_value(v);
    if (!isfinite(*out))
        return fail(L, field(at, sizeof at, path, key), "expected a finite number");
    return PD_OK;
}

/* A value x > 0 (what, in unit) within the usable range [lo, hi] (the
 * SCENE_* ranges); the message names the field at path. */
static int in_range(loader *L, const char *path, const char *what, double x, double lo, double hi,
                    const char *unit)
{
    const char *sp = unit[0] ? " " : "";
    if (!(x > 0.0) || (x >= lo && x <= hi)) /* <= 0: the builder's message */
        return PD_OK;
    return fail(L, path, "%s %g%s%s is outside the usable range [%g, %g]%s%s", what, x, sp, unit,
                lo, hi, sp, unit);
}

/* A string field (required). */
static int get_string(loader *L, json_t *obj, const char *path, const char *key, const char **out)
{
    char at[160];
    json_t *v = json_object_get(obj, key);
    if (!v)
        return fail(L, path, "missing field '%s' (a string)", key);
    if (!json_is_string(v))
        return fail(L, field(at, sizeof at, path, key), "expected a string");
    *out = json_string_value(v);
    return PD_OK;
}

/* An array of n numbers (n = -1: any length >= 1; *count gets it) with
 * each entry > 0 when positive; *out malloc'd. */
static int get_numbers(loader *L, json_t *arr, const char *at, int integers, double **out,
                       int *count)
{
    char el[200];
    *out = NULL;
    if (!json_is_array(arr) || json_array_size(arr) == 0)
        return fail(L, at, "expected a non-empty array of %s", integers ? "integers" : "numbers");
    size_t n = json_array_size(arr);
    if (n > 10000000)
        return fail(L, at, "too many entries (%zu)", n);
    *out = malloc(n * sizeof(double));
    if (!*out)
        return pd_err_set(L->err, PD_ENOMEM, "%s: out of memory", L->path);
    for (size_t i = 0; i < n; i++) {
        json_t *v = json_array_get(arr, i);
        snprintf(el, sizeof el, "%s[%zu]", at, i);
        if (integers ? !json_is_integer(v) : !json_is_number(v)) {
            free(*out);
            *out = NULL;
            return fail(L, el, "expected %s", integers ? "an integer" : "a number");
        }
        (*out)[i] = json_number_value(v);
        if (!isfinite((*out)[i])) {
            free(*out);
            *out = NULL;
            return fail(L, el, "expected a finite number");
        }
    }
    *count = (int)n;
    return PD_OK;
}

/* ---- the sections ------------------------------------------------------------ */

/* The record file of the excitation: a path relative to the scene file's
 * folder (unless absolute) into buf. */
static void record_path(const loader *L, const char *file, char *buf, size_t cap)
{
    const char *slash = strrchr(L->path, '/');
    if (file[0] == '/' || !slash)
        snprintf(buf, cap, "%s", file);
    else
        snprintf(buf, cap, "%.*s/%s", (int)(slash - L->path), L->path, file);
}

/* "record", "scale", "units", "format" of the excitation: the record read,
 * its pulse fitted, into x and *rec (malloc'd, the scene's to free). */
static int read_record(loader *L, json_t *ex, pd_scene_excitation *x, pd_record **rec)
{
    const char *file, *units = "g", *format = "auto";
    char path[4096], name[64];
    pd_record_units u;
    pd_record_format f;
    pd_record_pulse pulse;
    pd_err e;
    int rc;
    x->scale = 1.0;
    if ((rc = get_string(L, ex, "excitation", "record", &file)) ||
        (rc = get_number(L, ex, "excitation", "scale", 0, 1.0, &x->scale)) ||
        (json_object_get(ex, "units") && (rc = get_string(L, ex, "excitation", "units", &units))) ||
        (json_object_get(ex, "format") &&
         (rc = get_string(L, ex, "excitation", "format", &format))))
        return rc;
    if (!(x->scale > 0.0))
        return fail(L, "excitation.scale", "must be > 0 (got %g)", x->scale);
    if ((rc = in_range(L, "excitation.scale", "the scale", x->scale, SCENE_SCALE_MIN,
                       SCENE_SCALE_MAX, "")))
        return rc;
    if (pd_record_units_parse(units, &u))
        return fail(L, "excitation.units", "'%s' is not one of g, m/s2, cm/s2",
                    printable(units, name, sizeof name));
    if (pd_record_format_parse(format, &f))
        return fail(L, "excitation.format", "'%s' is not one of auto, at2, v2, text",
                    printable(format, name, sizeof name));
    for (const char *k = "pulse\0ap\0Tp\0"; *k; k += strlen(k) + 1)
        if (json_object_get(ex, k))
            return fail(L, "excitation",
                        "'%s' goes with a pulse, not with a record (its fitted "
                        "pulse gives ap and Tp; 'scale' scales it)",
                        k);
    record_path(L, file, path, sizeof path);
    if (!(*rec = calloc(1, sizeof **rec)))
        return pd_err_set(L->err, PD_ENOMEM, "%s: out of memory", L->path);
    if ((rc = pd_record_read(path, f, u, *rec, &e)) ||
        (rc = pd_record_fit_pulse(*rec, &pulse, &e))) {
        pd_record_free(*rec);
        free(*rec);
        *rec = NULL;
        return rc == PD_ENOMEM ? pd_err_set(L->err, rc, "%s", e.msg)
                               : fail(L, "excitation.record", "%s", e.msg);
    }
    pd_scene_excite_record(x, *rec, &pulse, x->scale);
    if ((rc = in_range(L, "excitation.record", "the fitted pulse's period Tp =", x->Tp,
                       SCENE_PERIOD_MIN, SCENE_PERIOD_MAX, "s")) ||
        (rc = in_range(L, "excitation.scale", "the fitted pulse's amplitude scale * ap =", x->ap,
                       SCENE_AP_MIN, SCENE_AP_MAX, "m/s^2"))) {
        pd_record_free(*rec);
        free(*rec);
        *rec = NULL;
        x->record = NULL;
    }
    return rc;
}

static int read_excitation(loader *L, json_t *root, pd_scene_excitation *x, pd_record **rec)
{
    static const char *const keys[] = {"pulse", "dir",   "ap",     "Tp", "record",
                                       "scale", "units", "format", NULL};
    json_t *ex = json_object_get(root, "excitation");
    const char *pulse, *dir = "+x";
    char name[64];
    int rc;
    if (!ex)
        return fail(L, "", "missing field 'excitation'");
    if (!json_is_object(ex))
        return fail(L, "excitation", "expected an object");
    if ((rc = only_keys(L, ex, "excitation", keys)))
        return rc;
    if (json_object_get(ex, "dir") && (rc = get_string(L, ex, "excitation", "dir", &dir)))
        return rc;
    if (strcmp(dir, "+x") && strcmp(dir, "-x"))
        return fail(L, "excitation.dir", "'%s' is not +x or -x", printable(dir, name, sizeof name));
    x->dir = strcmp(dir, "+x") ? -1 : 1;
    if (json_object_get(ex, "record"))
        return read_record(L, ex, x, rec);
    for (const char *k = "scale\0units\0format\0"; *k; k += strlen(k) + 1)
        if (json_object_get(ex, k))
            return fail(L, "excitation", "'%s' goes with a record", k);
    if ((rc = get_string(L, ex, "excitation", "pulse", &pulse)))
        return rc;
    if (pd_pulse_parse(pulse, &x->pulse))
        return fail(L, "excitation.pulse", "'%s' is not one of sine, cosine, harmonic",
                    printable(pulse, name, sizeof name));
    if ((rc = get_number(L, ex, "excitation", "ap", 1, 0.0, &x->ap)) ||
        (rc = get_number(L, ex, "excitation", "Tp", 1, 0.0, &x->Tp)))
        return rc;
    if (!(x->ap > 0.0))
        return fail(L, "excitation.ap", "the pulse amplitude must be > 0 (got %g)", x->ap);
    if (!(x->Tp > 0.0))
        return fail(L, "excitation.Tp", "the pulse period must be > 0 (got %g)", x->Tp);
    if ((rc = in_range(L, "excitation.ap", "the pulse amplitude", x->ap, SCENE_AP_MIN, SCENE_AP_MAX,
                       "m/s^2")))
        return rc;
    return in_range(L, "excitation.Tp", "the pulse period", x->Tp, SCENE_PERIOD_MIN,
                    SCENE_PERIOD_MAX, "s");
}

/* The damping fields of structure s at path. */
static int read_damping(loader *L, pd_scene *sc, json_t *st, const char *path)
{
    json_t *d = json_object_get(st, "damping"), *modes = json_object_get(st, "rayleigh_modes");
    char at[160], name[64];
    pd_damping kind = PD_DAMPING_RAYLEIGH;
    double *m = NULL;
    int nm = 0, rc;
    pd_err e;
    if (d) {
        if (!json_is_string(d))
            return fail(L, field(at, sizeof at, path, "damping"), "expected a string");
        if (!strcmp(json_string_value(d), "stiffness"))
            kind = PD_DAMPING_STIFFNESS;
        else if (strcmp(json_string_value(d), "rayleigh"))
            return fail(L, field(at, sizeof at, path, "damping"),
                        "'%s' is not rayleigh or stiffness",
                        printable(json_string_value(d), name, sizeof name));
    }
    int m1 = 1, m2 = 2;
    if (modes) {
        if ((rc = get_numbers(L, modes, field(at, sizeof at, path, "rayleigh_modes"), 1, &m, &nm)))
            return rc;
        if (nm != 2) {
            free(m);
            return fail(L, at, "expected two mode numbers [i, j]");
        }
        m1 = (int)m[0];
        m2 = (int)m[1];
        free(m);
    }
    if (!d && !modes)
        return PD_OK;
    if (pd_scene_set_damping(sc, kind, m1, m2, &e))
        return fail_builder(L, path, &e);
    return PD_OK;
}

/* "storey_heights" of the last structure at path: a number (every storey)
 * or one per storey, each finite and > 0 [m]; absent: PD_STOREY_HEIGHT. */
static int read_heights(loader *L, pd_scene *sc, json_t *st, const char *path)
{
    json_t *h = json_object_get(st, "storey_heights");
    pd_structure *s = &sc->st[sc->nstruct - 1];
    char at[160], el[200];
    double *v = NULL, one;
    int n = 0, rc;
    pd_err e;
    if (!h)
        return PD_OK;
    field(at, sizeof at, path, "storey_heights");
    if (json_is_number(h)) {
        one = json_number_value(h);
        if (!(one > 0.0) || !isfinite(one))
            return fail(L, at, "the storey height must be a finite number > 0 [m] (got %g)", one);
        for (int i = 0; i < s->storeys; i++)
            s->height[i] = one;
        return PD_OK;
    }
    if ((rc = get_numbers(L, h, at, 0, &v, &n)))
        return rc;
    if (n != s->storeys)
        rc = fail(L, at,
                  "%d heights for %d storeys: give one per storey (or one number for "
                  "all)",
                  n, s->storeys);
    for (int i = 0; i < n && !rc; i++)
        if (!(v[i] > 0.0)) {
            snprintf(el, sizeof el, "%s[%d]", at, i);
            rc = fail(L, el, "the storey height must be a finite number > 0 [m] (got %g)", v[i]);
        }
    if (!rc && pd_scene_set_heights(sc, v, &e))
        rc = fail_builder(L, path, &e);
    free(v);
    return rc;
}

/* A per-storey field of the last structure at path: a number (every
 * storey) or one per storey, into v (storeys entries, malloc'd). */
static int per_storey(loader *L, json_t *x, const char *at, int storeys, double **v)
{
    int n = 0, rc;
    if (json_is_number(x)) {
        if (!(*v = malloc((size_t)storeys * sizeof(double))))
            return fail(L, at, "out of memory");
        for (int i = 0; i < storeys; i++)
            (*v)[i] = json_number_value(x);
        return PD_OK;
    }
    if ((rc = get_numbers(L, x, at, 0, v, &n)))
        return rc;
    if (n != storeys)
        return fail(L, at, "%d values for %d storeys: give one per storey (or one number for all)",
                    n, storeys);
    return PD_OK;
}

/* "uy" (the yield drift [m]) and "alpha" (the post-yield stiffness ratio)
 * of the last structure at path: each a number or one per storey (SPEC §7). */
static int read_yield(loader *L, pd_scene *sc, json_t *st, const char *path)
{
    json_t *u = json_object_get(st, "uy"), *a = json_object_get(st, "alpha");
    int storeys = sc->st[sc->nstruct - 1].storeys, rc;
    char at[160], el[200];
    double *uy = NULL, *alpha = NULL;
    pd_err e;
    if (!u)
        return a ? fail(L, field(at, sizeof at, path, "alpha"),
                        "needs the yield drift 'uy' of the same structure")
                 : PD_OK;
    if (!(rc = per_storey(L, u, field(at, sizeof at, path, "uy"), storeys, &uy)) && a)
        rc = per_storey(L, a, field(at, sizeof at, path, "alpha"), storeys, &alpha);
    for (int i = 0; i < storeys && !rc; i++) {
        snprintf(el, sizeof el, "%s.uy[%d]", path, i);
        if (!(uy[i] > 0.0) || !isfinite(uy[i]))
            rc = fail(L, el, "the yield drift must be a finite number > 0 [m] (got %g)", uy[i]);
        snprintf(el, sizeof el, "%s.alpha[%d]", path, i);
        if (!rc && alpha && !(alpha[i] >= 0.0 && alpha[i] <= 1.0))
            rc = fail(L, el, "the post-yield stiffness ratio must be in [0, 1] (got %g)", alpha[i]);
    }
    if (!rc && pd_scene_set_yield(sc, uy, alpha, &e))
        rc = fail_builder(L, path, &e);
    free(uy);
    free(alpha);
    return rc;
}

/* The damping fields, the storey heights and the yielding storeys of the
 * last structure at path. */
static int read_extras(loader *L, pd_scene *sc, json_t *st, const char *path)
{
    int rc = read_damping(L, sc, st, path);
    if (!rc)
        rc = read_heights(L, sc, st, path);
    return rc ? rc : read_yield(L, sc, st, path);
}

/* Every storey's mass and stiffness of a building at path in the usable ranges. */
static int storeys_in_range(loader *L, const char *path, int n, const double *m, const double *k)
{
    char at[200];
    int rc = PD_OK;
    for (int i = 0; i < n && !rc; i++) {
        snprintf(at, sizeof at, "%s.masses[%d]", path, i);
        rc = in_range(L, at, "the mass", m[i], SCENE_MASS_MIN, SCENE_MASS_MAX, "kg");
        snprintf(at, sizeof at, "%s.stiffnesses[%d]", path, i);
        if (!rc)
            rc = in_range(L, at, "the stiffness", k[i], SCENE_STIFF_MIN, SCENE_STIFF_MAX, "N/m");
    }
    return rc;
}

/* One structure: SDOF (T0), building (masses, stiffnesses) or uniform
 * (storeys, mass, T0). */
static int read_structure(loader *L, pd_scene *sc, json_t *st, int k)
{
    static const char *const keys[] = {
        "name",        "T0",      "xi",      "mass",           "masses",
        "stiffnesses", "storeys", "damping", "rayleigh_modes", "storey_heights",
        "uy",          "alpha",   NULL};
    char path[64], at[160];
    const char *name;
    double xi, T0 = 0.0, mass = 1.0;
    int rc;
    pd_err e;
    snprintf(path, sizeof path, "structures[%d]", k);
    if (!json_is_object(st))
        return fail(L, path, "expected an object");
    if ((rc = only_keys(L, st, path, keys)) || (rc = get_string(L, st, path, "name", &name)) ||
        (rc = get_number(L, st, path, "xi", 0, 0.05, &xi)))
        return rc;
    json_t *masses = json_object_get(st, "masses"), *storeys = json_object_get(st, "storeys");
    if (masses) { /* a building storey by storey */
        double *m = NULL, *kk = NULL;
        int nm = 0, nk = 0;
        if (storeys || json_object_get(st, "T0") || json_object_get(st, "mass"))
            return fail(L, field(at, sizeof at, path, "masses"),
                        "give masses and stiffnesses, or storeys, mass and T0, or T0 (an SDOF)");
        if (!json_object_get(st, "stiffnesses"))
            return fail(L, path, "missing field 'stiffnesses' (one per storey)");
        if ((rc = get_numbers(L, masses, field(at, sizeof at, path, "masses"), 0, &m, &nm)) ||
            (rc = get_numbers(L, json_object_get(st, "stiffnesses"),
                              field(at, sizeof at, path, "stiffnesses"), 0, &kk, &nk))) {
            free(m);
            return rc;
        }
        if (nm != nk)
            rc = fail(L, field(at, sizeof at, path, "stiffnesses"),
                      "%d stiffnesses for %d masses: give one per storey", nk, nm);
        else if (!(rc = storeys_in_range(L, path, nm, m, kk)) &&
                 pd_scene_add_building(sc, name, nm, m, kk, xi, &e))
            rc = fail_builder(L, path, &e);
        free(m);
        free(kk);
        return rc ? rc : read_extras(L, sc, st, path);
    }
    if (json_object_get(st, "stiffnesses"))
        return fail(L, path, "missing field 'masses' (one per storey)");
    if ((rc = get_number(L, st, path, "T0", 1, 0.0, &T0)) ||
        (rc = get_number(L, st, path, "mass", 0, 1.0, &mass)) ||
        (rc = in_range(L, field(at, sizeof at, path, "T0"), "the period", T0, SCENE_PERIOD_MIN,
                       SCENE_PERIOD_MAX, "s")) ||
        (rc = in_range(L, field(at, sizeof at, path, "mass"), "the mass", mass, SCENE_MASS_MIN,
                       SCENE_MASS_MAX, "kg")))
        return rc;
    if (storeys) {
        if (!json_is_integer(storeys) || json_integer_value(storeys) < 1 ||
            json_integer_value(storeys) > 100000)
            return fail(L, field(at, sizeof at, path, "storeys"),
                        "expected a positive integer (at most 100000)");
        rc = pd_scene_add_uniform(sc, name, (int)json_integer_value(storeys), mass, T0, xi, &e);
    } else
        rc = pd_scene_add_sdof(sc, name, T0, xi, mass, &e);
    if (rc)
        return fail_builder(L, path, &e);
    return read_extras(L, sc, st, path);
}

/* The structure named by field key of contact entry at path. */
static int contact_side(loader *L, const pd_scene *sc, json_t *ct, const char *path,
                        const char *key, int *s)
{
    const char *name;
    char at[160], buf[64];
    int rc = get_string(L, ct, path, key, &name);
    if (rc)
        return rc;
    *s = pd_scene_find(sc, name);
    if (*s == -2)
        return fail(L, field(at, sizeof at, path, key), "no structure named '%s'",
                    printable(name, buf, sizeof buf));
    return PD_OK;
}

/* The storey pairs of a contacts[] entry: levels [i, ...] (aligned floors,
 * default [1]) or pairs [[la, lb], ...]; *la, *lb malloc'd. */
static int read_levels(loader *L, json_t *ct, const char *path, int **la, int **lb, int *nl)
{
    json_t *levels = json_object_get(ct, "levels"), *pairs = json_object_get(ct, "pairs");
    json_t *list = levels ? levels : pairs;
    char at[160], el[200];
    *la = *lb = NULL;
    if (levels && pairs)
        return fail(L, field(at, sizeof at, path, "pairs"), "give levels or pairs, not both");
    size_t n = list ? json_array_size(list) : 1;
    field(at, sizeof at, path, levels ? "levels" : "pairs");
    if (list && (!json_is_array(list) || n == 0))
        return fail(L, at,
                    levels ? "expected a non-empty array of storeys [i, ...]"
                           : "expected a non-empty array of pairs [[level_a, level_b], ...]");
    if (n > SCENE_LEVELS_MAX)
        return fail(L, at, "%zu entries: at most %d", n, SCENE_LEVELS_MAX);
    *la = malloc(n * sizeof(int));
    *lb = malloc(n * sizeof(int));
    if (!*la || !*lb)
        return pd_err_set(L->err, PD_ENOMEM, "%s: out of memory", L->path);
    *nl = (int)n;
    for (size_t i = 0; i < n; i++) {
        json_t *v = list ? json_array_get(list, i) : NULL;
        snprintf(el, sizeof el, "%s[%zu]", at, i);
        if (!list) {
            (*la)[i] = (*lb)[i] = 1;
        } else if (levels) {
            if (!json_is_integer(v) || json_integer_value(v) < 1 || json_integer_value(v) > 100000)
                return fail(L, el, "expected a storey number >= 1");
            (*la)[i] = (*lb)[i] = (int)json_integer_value(v);
        } else {
            json_t *x = json_array_get(v, 0), *y = json_array_get(v, 1);
            if (!json_is_array(v) || json_array_size(v) != 2 || !json_is_integer(x) ||
                !json_is_integer(y) || json_integer_value(x) < 1 || json_integer_value(y) < 1 ||
                json_integer_value(x) > 100000 || json_integer_value(y) > 100000)
                return fail(L, el, "expected a pair of storey numbers [level_a, level_b]");
            (*la)[i] = (int)json_integer_value(x);
            (*lb)[i] = (int)json_integer_value(y);
        }
    }
    return PD_OK;
}

/* One contacts[] entry: its sides, storey pairs, gap(s) and eps. */
static int read_contact(loader *L, pd_scene *sc, json_t *ct, int k)
{
    static const char *const keys[] = {"a", "b", "levels", "pairs", "gap", "eps", NULL};
    char path[64], at[160], el[200];
    int a, b, rc, nl = 0, *la = NULL, *lb = NULL;
    double eps;
    pd_err e;
    snprintf(path, sizeof path, "contacts[%d]", k);
    if (!json_is_object(ct))
        return fail(L, path, "expected an object");
    if ((rc = only_keys(L, ct, path, keys)) || (rc = contact_side(L, sc, ct, path, "a", &a)) ||
        (rc = contact_side(L, sc, ct, path, "b", &b)) ||
        (rc = get_number(L, ct, path, "eps", 1, 0.0, &eps)))
        return rc;
    json_t *gap = json_object_get(ct, "gap");
    if (!gap)
        return fail(L, path, "missing field 'gap' (metres: a number, or one per level)");
    if (!(rc = read_levels(L, ct, path, &la, &lb, &nl))) {
        field(at, sizeof at, path, "gap");
        if (json_is_array(gap) && json_array_size(gap) != (size_t)nl)
            rc = fail(L, at, "%zu gaps for %d levels", json_array_size(gap), nl);
        else if (!json_is_array(gap) && !json_is_number(gap))
            rc = fail(L, at, "expected a number, or an array of one per level");
    }
    for (int i = 0; i < nl && !rc; i++) {
        json_t *g = json_is_array(gap) ? json_array_get(gap, (size_t)i) : gap;
        snprintf(el, sizeof el, "%s[%d]", at, i);
        if (!json_is_number(g) || !isfinite(json_number_value(g)))
            rc = fail(L, json_is_array(gap) ? el : at, "expected a finite number");
        else if (!(rc = in_range(L, json_is_array(gap) ? el : at, "the gap", json_number_value(g),
                                 0.0, SCENE_GAP_MAX, "m")) &&
                 pd_scene_add_contact(sc, a, a == PD_WALL ? 0 : la[i], b, b == PD_WALL ? 0 : lb[i],
                                      json_number_value(g), eps, k, &e))
            rc = fail_builder(L, path, &e);
    }
    free(la);
    free(lb);
    return rc;
}

/* The structure and contact arrays of the file: present and of the right type. */
static int check_sections(loader *L, json_t *root)
{
    json_t *sts = json_object_get(root, "structures"), *cts = json_object_get(root, "contacts");
    if (!sts)
        return fail(L, "", "missing field 'structures'");
    if (!json_is_array(sts) || json_array_size(sts) == 0)
        return fail(L, "structures", "expected a non-empty array (the row, left to right)");
    if (cts && !json_is_array(cts))
        return fail(L, "contacts", "expected an array");
    if (json_object_get(root, "description") &&
        !json_is_string(json_object_get(root, "description")))
        return fail(L, "description", "expected a string");
    return PD_OK;
}

/* The fundamental period of structure k, once the scene is finished, in
 * the usable range: for a building given storey by storey it comes from
 * masses and stiffnesses together (1 kg storeys on 6e8 N/m: 0.6 ms). */
static int check_periods(loader *L, const pd_scene *sc, json_t *st, int k)
{
    char path[64];
    if (!json_object_get(st, "masses")) /* T0 given, and checked */
        return PD_OK;
    snprintf(path, sizeof path, "structures[%d].stiffnesses", k);
    return in_range(L, path, "with these masses, the fundamental period", sc->st[k].T0,
                    SCENE_PERIOD_MIN, SCENE_PERIOD_MAX, "s");
}

static int read_scene(loader *L, json_t *root, pd_scene **out)
{
    static const char *const keys[] = {"excitation", "structures",  "contacts",
                                       "tend",       "description", NULL};
    pd_scene_excitation x = {0};
    pd_record *rec = NULL;
    pd_scene *sc = NULL;
    int rc;
    pd_err e;
    if (!json_is_object(root))
        return fail(L, "", "expected a JSON object with excitation, structures, contacts");
    if ((rc = only_keys(L, root, "", keys)) || (rc = check_sections(L, root)) ||
        (rc = read_excitation(L, root, &x, &rec)))
        return rc;
    if (!(sc = pd_scene_new(&x))) {
        if (rec) {
            pd_record_free(rec);
            free(rec);
        }
        return pd_err_set(L->err, PD_ENOMEM, "%s: out of memory", L->path);
    }
    sc->own_record = rec; /* freed with the scene from here on */
    json_t *sts = json_object_get(root, "structures"), *cts = json_object_get(root, "contacts");
    if ((rc = get_number(L, root, "", "tend", 0, 0.0, &sc->tend)) == PD_OK && sc->tend < 0.0)
        rc = fail(L, "tend", "must be > 0 (got %g)", sc->tend);
    if (!rc && sc->tend > SCENE_TEND_MAX)
        rc = fail(L, "tend", "%g s is outside the usable range (0, %g] s (0: derived)", sc->tend,
                  SCENE_TEND_MAX);
    for (size_t k = 0; !rc && k < json_array_size(sts); k++)
        rc = read_structure(L, sc, json_array_get(sts, k), (int)k);
    for (size_t k = 0; !rc && cts && k < json_array_size(cts); k++)
        rc = read_contact(L, sc, json_array_get(cts, k), (int)k);
    if (!rc && pd_scene_finish(sc, &e))
        rc = fail_builder(L, "", &e);
    for (size_t k = 0; !rc && k < json_array_size(sts); k++)
        rc = check_periods(L, sc, json_array_get(sts, k), (int)k);
    if (rc) {
        pd_scene_free(sc);
        return rc;
    }
    *out = sc;
    return PD_OK;
}

/* The whole file, NUL-terminated: no NUL byte inside, at most
 * SCENE_FILE_MAX bytes (pd_core.h). */
static int slurp(loader *L)
{
    return pd_text_read_all(L->path, SCENE_FILE_MAX, PD_TEXT_AT_LINE_COL, &L->text, &L->len,
                            L->err);
}

int pd_scene_load(const char *path, pd_scene **out, pd_err *err)
{
    loader L = {.path = path, .err = err};
    json_error_t je;
    int rc;
    if (!path || !out)
        return PD_NULL_ARG(err, !path ? "path" : "out");
    *out = NULL;
    pd_err_clear(err);
    if ((rc = slurp(&L)))
        return rc;
    json_t *root = json_loadb(L.text, L.len, JSON_REJECT_DUPLICATES, &je);
    if (!root) {
        char text[160];
        rc = pd_err_set(err, PD_EPARSE, "%s:%d:%d: %s", path, je.line > 0 ? je.line : 1,
                        je.column > 0 ? je.column : 1, printable(je.text, text, sizeof text));
    } else {
        rc = read_scene(&L, root, out);
        json_decref(root);
    }
    free(L.text);
    return rc;
}
