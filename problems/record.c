/* record.c — reading strong-motion records (SPEC §5, docs/records.md).
 *
 * PEER NGA .AT2: header lines, the one that names NPTS and DT in either
 *   "NPTS=  1991, DT=   .0100 SEC"  (also without the comma) or
 *   "1991    0.0100    NPTS, DT"    (older NGA files),
 * then NPTS accelerations in g, several to a line.
 * COSMOS/CDMG V2: the first channel's acceleration block, announced by
 *   " 3251 POINTS OF ACCEL DATA EQUALLY SPACED AT  .020 SEC.  (UNITS: CM/SEC/SEC)"
 * (the velocity and displacement blocks that follow are not read), held to
 * what its header declares (read_v2): the first channel's, within its
 * boundaries; in the CDMG layout on line 46 after 25 text, 7 integer and 13
 * real lines, its points and dt those of the integer and real headers.
 * Text: lines "t a", '#' comments, t uniform (see text_uniform).
 *
 * Files are read line by line in bounded memory (pd_core.h): lines up to
 * PD_TEXT_LINE_MAX, files up to RECORD_FILE_MAX bytes and records up to
 * RECORD_NPTS_MAX samples; a NUL byte is refused where it is read.  CR (also
 * CR CR LF line ends), tabs, commas and the DOS end-of-file byte 0x1A are
 * blanks.  Numbers that touch ("1.234E-02-5.678E-03", "0.123-0.456") are
 * split where a sign follows a complete number; Fortran's D exponent is
 * read.  Every error is one line "FILE:LINE: what was expected". */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "pd_problems.h"
#include "pd_core.h"
#include "pd_null.h"

/* Largest record file read: 1 GiB.  Strong-motion records are kilobytes to
 * a few megabytes (10^5 samples of 15 characters); the cap bounds what an
 * endless input (/dev/zero, a stream) can cost before it is refused. */
#define RECORD_FILE_MAX (1L << 30)
#define RECORD_NPTS_MAX 100000000L /* 10^8 samples: 800 MB of doubles */
#define RECORD_AT2_HEAD 10         /* lines searched for the AT2 NPTS line */
#define RECORD_V2_HEAD 200         /* lines searched for the V2 acceleration block */
#define RECORD_TEXT_TOL 1e-2       /* text: largest deviation of t_k from t_0 + k dt, in dt */
#define RECORD_WORD_MAX 64         /* longest number read */

/* The CDMG V2 layout (CSMIP's Volume 2 files, the shared ce36456p_CE36456.V2):
 * 25 text lines, 100 integers in 16I5, 100 reals in 8F10.3, then the
 * acceleration block's header; the integers' 53rd value is its number of
 * points, the reals' 61st its dt (0-based indices below). */
#define RECORD_V2_TEXT_LINES 25
#define RECORD_V2_INTS 100
#define RECORD_V2_INT_COLS 16
#define RECORD_V2_INT_WIDTH 5
#define RECORD_V2_REALS 100
#define RECORD_V2_REAL_COLS 8
#define RECORD_V2_REAL_WIDTH 10
#define RECORD_V2_INT_NPTS 52
#define RECORD_V2_REAL_DT 60
#define RECORD_V2_INT_LINES ((RECORD_V2_INTS + RECORD_V2_INT_COLS - 1) / RECORD_V2_INT_COLS)
#define RECORD_V2_REAL_LINES ((RECORD_V2_REALS + RECORD_V2_REAL_COLS - 1) / RECORD_V2_REAL_COLS)
#define RECORD_V2_HEAD_LINES (RECORD_V2_TEXT_LINES + RECORD_V2_INT_LINES + RECORD_V2_REAL_LINES)
#define RECORD_V2_DT_TOL 5.000001e-4 /* dts agree to the 3 decimals V2 headers print */

/* A file read line by line. */
typedef struct rec_reader {
    const char *path;
    pd_text t;
    char *line;  /* the current line, NUL-terminated (t's buffer) */
    long lineno; /* of the current line, 1-based; 0 before the first */
    pd_err *err;
} rec_reader;

/* Samples gathered so far (grown by doubling). */
typedef struct rec_buf {
    double *v;
    long n, cap;
} rec_buf;

/* ---- names ---------------------------------------------------------------- */

const char *pd_record_format_name(pd_record_format f)
{
    switch (f) {
    case PD_RECORD_AUTO:
        return "auto";
    case PD_RECORD_AT2:
        return "at2";
    case PD_RECORD_V2:
        return "v2";
    case PD_RECORD_TEXT:
        return "text";
    }
    return "?";
}

int pd_record_format_parse(const char *name, pd_record_format *f)
{
    static const pd_record_format all[] = {PD_RECORD_AUTO, PD_RECORD_AT2, PD_RECORD_V2,
                                           PD_RECORD_TEXT};
    if (!name || !f)
        return PD_EINVAL;
    for (int i = 0; i < 4; i++)
        if (!strcmp(name, pd_record_format_name(all[i]))) {
            *f = all[i];
            return PD_OK;
        }
    return PD_EINVAL;
}

const char *pd_record_units_name(pd_record_units u)
{
    switch (u) {
    case PD_UNITS_G:
        return "g";
    case PD_UNITS_M_S2:
        return "m/s2";
    case PD_UNITS_CM_S2:
        return "cm/s2";
    }
    return "?";
}

/* Also "m/s^2" and "cm/s^2". */
int pd_record_units_parse(const char *name, pd_record_units *u)
{
    if (!name || !u)
        return PD_EINVAL;
    if (!strcmp(name, "g"))
        *u = PD_UNITS_G;
    else if (!strcmp(name, "m/s2") || !strcmp(name, "m/s^2"))
        *u = PD_UNITS_M_S2;
    else if (!strcmp(name, "cm/s2") || !strcmp(name, "cm/s^2"))
        *u = PD_UNITS_CM_S2;
    else
        return PD_EINVAL;
    return PD_OK;
}

/* Metres per second squared in one unit. */
static double units_scale(pd_record_units u)
{
    return u == PD_UNITS_G ? PD_G_STANDARD : u == PD_UNITS_CM_S2 ? 0.01 : 1.0;
}

/* ---- the record as a function of time --------------------------------------- */

void pd_record_free(pd_record *rec)
{
    if (!rec)
        return;
    free(rec->acc);
    rec->acc = NULL;
    rec->npts = 0;
}

double pd_record_duration(const pd_record *rec)
{
    if (!rec)
        return NAN;
    return rec->npts > 1 ? (double)(rec->npts - 1) * rec->dt : 0.0;
}

double pd_record_acc(const pd_record *rec, double t)
{
    if (!rec)
        return NAN;
    if (!(t >= 0.0) || rec->npts < 1)
        return 0.0;
    double x = t / rec->dt;
    double last = (double)(rec->npts - 1);
    if (x > last * (1.0 + 1e-12)) /* the last sample's time, to rounding */
        return 0.0;
    long k = (long)x;
    if (k >= rec->npts - 1)
        return rec->acc[rec->npts - 1];
    double r = x - (double)k;
    return rec->acc[k] + r * (rec->acc[k + 1] - rec->acc[k]);
}

/* ---- lines and words -------------------------------------------------------- */

/* Blank inside a line: space, tab, CR, VT, FF, comma, DOS end of file. */
static int is_blank(int c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f' || c == ',' ||
           c == 0x1a;
}

/* Past the blanks at p. */
static const char *skip_blanks(const char *p)
{
    while (*p && is_blank((unsigned char)*p))
        p++;
    return p;
}

/* The line holds nothing but blanks. */
static int line_blank(const char *s)
{
    return *skip_blanks(s) == '\0';
}

/* Where needle starts in hay, ignoring case, or NULL. */
static const char *find_nocase(const char *hay, const char *needle)
{
    size_t n = strlen(needle);
    for (; *hay; hay++) {
        size_t i = 0;
        while (i < n && hay[i] &&
               tolower((unsigned char)hay[i]) == tolower((unsigned char)needle[i]))
            i++;
        if (i == n)
            return hay;
    }
    return NULL;
}

/* Open the file for reading. */
static int reader_open(rec_reader *r, const char *path, pd_err *err)
{
    *r = (rec_reader){.path = path, .err = err};
    return pd_text_open(&r->t, path, RECORD_FILE_MAX, PD_TEXT_AT_LINE, err);
}

/* Back to the start of the file. */
static int reader_rewind(rec_reader *r)
{
    r->lineno = 0;
    r->line = NULL;
    return pd_text_rewind(&r->t);
}

/* Close the file and free the line buffer. */
static void reader_close(rec_reader *r)
{
    pd_text_close(&r->t);
    r->line = NULL;
}

/* The next line into r->line: 1, 0 at the end of the file, or an error
 * (a read error, a NUL byte, a line or a file beyond its cap). */
static int next_line(rec_reader *r)
{
    int st = pd_text_line(&r->t);
    if (st == 1) {
        r->line = r->t.line;
        r->lineno = r->t.lineno;
    }
    return st;
}

/* The word (up to a blank) at p, for messages: at most 40 characters. */
static int word_len(const char *p)
{
    int n = 0;
    while (p[n] && !is_blank((unsigned char)p[n]) && n < 40)
        n++;
    return n;
}

/* Length of a number at p ([+-] digits [. digits] [eEdD [+-] digits]), 0 if none. */
static size_t number_len(const char *p)
{
    size_t i = 0, digits = 0;
    if (p[i] == '+' || p[i] == '-')
        i++;
    for (; isdigit((unsigned char)p[i]); i++)
        digits++;
    if (p[i] == '.')
        for (i++; isdigit((unsigned char)p[i]); i++)
            digits++;
    if (!digits)
        return 0;
    if (p[i] && strchr("eEdD", p[i])) {
        size_t j = i + 1;
        if (p[j] == '+' || p[j] == '-')
            j++;
        if (isdigit((unsigned char)p[j])) {
            while (isdigit((unsigned char)p[j]))
                j++;
            i = j;
        }
    }
    return i;
}

/* A word that names a NaN or an infinity. */
static int names_nonfinite(const char *p, int n)
{
    char w[48];
    int k = 0;
    for (int i = 0; i < n && k < 47; i++)
        if (p[i] != '+' && p[i] != '-')
            w[k++] = (char)tolower((unsigned char)p[i]);
    w[k] = '\0';
    return strstr(w, "nan") || strstr(w, "inf");
}

/* The next number of a data line from *p into *x: 1 read, 0 at the end of
 * the line, PD_EPARSE on a word that is not a finite number. */
static int scan_number(rec_reader *r, const char **p, double *x)
{
    const char *s = skip_blanks(*p);
    if (!*s) {
        *p = s;
        return 0;
    }
    size_t n = number_len(s);
    char c = s[n];
    if (!n || n >= RECORD_WORD_MAX ||
        !(c == '\0' || is_blank((unsigned char)c) || c == '+' || c == '-')) {
        int wl = word_len(s);
        if (names_nonfinite(s, wl))
            return pd_err_set(r->err, PD_EPARSE, "%s:%ld: expected a finite number, got '%.*s'",
                              r->path, r->lineno, wl, s);
        return pd_err_set(r->err, PD_EPARSE, "%s:%ld: expected a number, got '%.*s'", r->path,
                          r->lineno, wl, s);
    }
    char buf[RECORD_WORD_MAX];
    for (size_t i = 0; i < n; i++)
        buf[i] = (s[i] == 'd' || s[i] == 'D') ? 'e' : s[i];
    buf[n] = '\0';
    double v = strtod(buf, NULL);
    if (!isfinite(v))
        return pd_err_set(r->err, PD_EPARSE, "%s:%ld: expected a finite number, got '%s'", r->path,
                          r->lineno, buf);
    *x = v;
    *p = s + n;
    return 1;
}

/* ---- sample buffers --------------------------------------------------------- */

/* Append v, growing to at most cap_max samples. */
static int buf_push(rec_buf *b, double v, long cap_max)
{
    if (b->n == b->cap) {
        long cap = b->cap ? 2 * b->cap : 4096;
        if (cap > cap_max)
            cap = cap_max;
        double *grown = cap > b->n ? realloc(b->v, (size_t)cap * sizeof *grown) : NULL;
        if (!grown)
            return PD_ENOMEM;
        b->v = grown;
        b->cap = cap;
    }
    b->v[b->n++] = v;
    return PD_OK;
}

/* ---- PEER .AT2 --------------------------------------------------------------- */

/* A count read as a number: an integer (PD_OK) or not (PD_EPARSE). */
static int parse_count(double v, long *n)
{
    if (!isfinite(v) || v != floor(v) || fabs(v) > 1e15)
        return PD_EPARSE;
    *n = (long)v;
    return PD_OK;
}

/* The number after key and '=' (or ':') in s. */
static int keyed_number(const char *s, const char *key, double *x)
{
    const char *k = find_nocase(s, key);
    if (!k)
        return PD_EPARSE;
    const char *p = k + strlen(key);
    while (*p == ' ' || *p == '\t')
        p++;
    if (*p != '=' && *p != ':')
        return PD_EPARSE;
    char *end = NULL;
    *x = strtod(p + 1, &end);
    return end == p + 1 ? PD_EPARSE : PD_OK;
}

/* NPTS and DT from the header line s: keyed ("NPTS= N, DT= H") or
 * positional ("N H NPTS, DT"). */
static int at2_npts_dt(const char *s, long *npts, double *dt)
{
    double n = 0.0;
    if (keyed_number(s, "NPTS", &n) == PD_OK)
        return parse_count(n, npts) == PD_OK && keyed_number(s, "DT", dt) == PD_OK ? PD_OK
                                                                                   : PD_EPARSE;
    const char *p = skip_blanks(s), *key = find_nocase(s, "NPTS");
    char *end = NULL;
    double a = strtod(p, &end);
    if (end == p || (key && end > key))
        return PD_EPARSE;
    p = end;
    double b = strtod(p, &end);
    if (end == p || (key && end > key))
        return PD_EPARSE;
    if (parse_count(a, npts) != PD_OK)
        return PD_EPARSE;
    *dt = b;
    return PD_OK;
}

/* The header line without its line end, for messages. */
static int shown_len(const char *s)
{
    int n = (int)strcspn(s, "\r\n");
    return n > 60 ? 60 : n;
}

/* A header's "UNITS OF X" must say G (an AT2 of velocities or displacements is refused). */
static int at2_units(rec_reader *r)
{
    const char *u = find_nocase(r->line, "UNITS OF");
    if (!u)
        return PD_OK;
    const char *p = skip_blanks(u + 8);
    if ((*p == 'G' || *p == 'g') && !isalnum((unsigned char)p[1]) && p[1] != '/')
        return PD_OK;
    return pd_err_set(r->err, PD_EPARSE,
                      "%s:%ld: expected accelerations 'IN UNITS OF G', got '%.*s'", r->path,
                      r->lineno, word_len(p), p);
}

/* A sampling interval dt (named what, read on line) within
 * [PD_RECORD_DT_MIN, PD_RECORD_DT_MAX]: with at most RECORD_NPTS_MAX
 * samples the duration is then at most 10^9 s. */
static int check_dt(rec_reader *r, long line, double dt, const char *what)
{
    if (!(dt >= PD_RECORD_DT_MIN && dt <= PD_RECORD_DT_MAX))
        return pd_err_set(r->err, PD_EPARSE,
                          "%s:%ld: %s = %g s: expected a sampling interval in [%g, %g] s", r->path,
                          line, what, dt, PD_RECORD_DT_MIN, PD_RECORD_DT_MAX);
    return PD_OK;
}

/* Check npts and dt from a header (AT2 or V2) at the current line. */
static int check_npts_dt(rec_reader *r, long npts, double dt)
{
    if (npts < 2)
        return pd_err_set(r->err, PD_EPARSE, "%s:%ld: NPTS = %ld: expected at least 2 samples",
                          r->path, r->lineno, npts);
    if (npts > RECORD_NPTS_MAX)
        return pd_err_set(r->err, PD_EPARSE, "%s:%ld: NPTS = %ld: more samples than the %ld read",
                          r->path, r->lineno, npts, RECORD_NPTS_MAX);
    if (!(dt > 0.0) || !isfinite(dt))
        return pd_err_set(r->err, PD_EPARSE, "%s:%ld: DT = %g: expected a positive time step",
                          r->path, r->lineno, dt);
    return check_dt(r, r->lineno, dt, "DT");
}

/* Read the AT2 header up to its NPTS line. */
static int at2_header(rec_reader *r, long *npts, double *dt)
{
    int st;
    while ((st = next_line(r)) == 1) {
        if ((st = at2_units(r)) != PD_OK)
            return st;
        if (find_nocase(r->line, "NPTS")) {
            if (at2_npts_dt(r->line, npts, dt) != PD_OK)
                return pd_err_set(r->err, PD_EPARSE,
                                  "%s:%ld: expected 'NPTS= N, DT= H SEC' or 'N H NPTS, DT', "
                                  "got '%.*s'",
                                  r->path, r->lineno, shown_len(r->line), r->line);
            return check_npts_dt(r, *npts, *dt);
        }
        if (r->lineno >= RECORD_AT2_HEAD)
            break;
    }
    if (st < 0)
        return st;
    if (r->lineno == 0)
        return pd_err_set(r->err, PD_EPARSE, "%s:1: empty file: expected a PEER .AT2 header",
                          r->path);
    return pd_err_set(r->err, PD_EPARSE,
                      "%s:1: no PEER .AT2 header: expected a line with NPTS and DT in the "
                      "first %d lines",
                      r->path, RECORD_AT2_HEAD);
}

/* A line that ends a V2 data block: the next block's header or "/&". */
static int v2_block_end(const char *s)
{
    return find_nocase(s, "POINTS OF") || skip_blanks(s)[0] == '/';
}

/* A value x of the file, scale m/s^2 per unit, finite in m/s^2 too (1e308 g
 * is not). */
static int finite_si(rec_reader *r, double x, double scale)
{
    if (isfinite(scale * x))
        return PD_OK;
    return pd_err_set(r->err, PD_EPARSE,
                      "%s:%ld: acceleration %g times %g m/s^2 per unit is not a finite number",
                      r->path, r->lineno, x, scale);
}

/* npts numbers from the following lines, times scale, into b; v2 stops at
 * the end of a V2 block. */
static int read_values(rec_reader *r, long npts, double scale, int v2, rec_buf *b)
{
    int st = 0;
    long last = r->lineno;
    while (b->n < npts && (st = next_line(r)) == 1) {
        if (v2 && v2_block_end(r->line))
            break;
        last = r->lineno;
        const char *p = r->line;
        double x;
        while (b->n < npts && (st = scan_number(r, &p, &x)) == 1) {
            if ((st = finite_si(r, x, scale)) != PD_OK)
                return st;
            if (buf_push(b, scale * x, npts) != PD_OK)
                return pd_err_set(r->err, PD_ENOMEM, "%s: out of memory for %ld samples", r->path,
                                  npts);
        }
        if (st < 0)
            return st;
        if (b->n == npts && scan_number(r, &p, &x) != 0)
            return pd_err_set(r->err, PD_EPARSE,
                              "%s:%ld: more values than NPTS = %ld (wrong NPTS?)", r->path,
                              r->lineno, npts);
    }
    if (st < 0)
        return st;
    if (b->n < npts)
        return pd_err_set(r->err, PD_EPARSE,
                          "%s:%ld: truncated: the data end after %ld of NPTS = %ld values", r->path,
                          last, b->n, npts);
    return PD_OK;
}

/* After the values: nothing but blank lines (AT2), or the end of the block (V2). */
static int check_after(rec_reader *r, long npts, int v2)
{
    int st;
    while ((st = next_line(r)) == 1) {
        if (v2 && v2_block_end(r->line))
            return PD_OK;
        if (!line_blank(r->line))
            return pd_err_set(r->err, PD_EPARSE,
                              "%s:%ld: more values than NPTS = %ld (wrong NPTS?)", r->path,
                              r->lineno, npts);
    }
    return st;
}

/* A PEER .AT2 file. */
static int read_at2(rec_reader *r, rec_buf *b, double *dt)
{
    long npts = 0;
    int st = at2_header(r, &npts, dt);
    if (st == PD_OK)
        st = read_values(r, npts, PD_G_STANDARD, 0, b);
    if (st == PD_OK)
        st = check_after(r, npts, 0);
    return st;
}

/* ---- COSMOS/CDMG V2 ---------------------------------------------------------- */

/* m/s^2 per unit of the block header's "(UNITS: ...)"; cm/s^2 when absent. */
static int v2_units(rec_reader *r, double *scale)
{
    const char *u = find_nocase(r->line, "UNITS:");
    *scale = 0.01;
    if (!u)
        return PD_OK;
    const char *p = skip_blanks(u + 6);
    int n = (int)strcspn(p, ") \t\r\n");
    static const struct {
        const char *name;
        double scale;
    } known[] = {{"CM/SEC/SEC", 0.01}, {"CM/S/S", 0.01},      {"CM/SEC2", 0.01},
                 {"CM/S2", 0.01},      {"MM/SEC/SEC", 0.001}, {"MM/S/S", 0.001},
                 {"M/SEC/SEC", 1.0},   {"M/S/S", 1.0},        {"G", PD_G_STANDARD}};
    for (size_t i = 0; i < sizeof known / sizeof known[0]; i++)
        if ((int)strlen(known[i].name) == n && find_nocase(p, known[i].name) == p) {
            *scale = known[i].scale;
            return PD_OK;
        }
    return pd_err_set(r->err, PD_EPARSE,
                      "%s:%ld: unknown acceleration units '%.*s' (expected CM/SEC/SEC, "
                      "M/SEC/SEC or G)",
                      r->path, r->lineno, n, p);
}

/* NPTS and DT of the acceleration block header at the current line. */
static int v2_npts_dt(rec_reader *r, long *npts, double *dt)
{
    const char *s = r->line, *at = find_nocase(s, "SPACED AT");
    char *end = NULL;
    double n = strtod(s, &end);
    if (end == s || !at || parse_count(n, npts) != PD_OK)
        return pd_err_set(r->err, PD_EPARSE,
                          "%s:%ld: expected 'N POINTS OF ACCEL DATA EQUALLY SPACED AT H SEC', "
                          "got '%.*s'",
                          r->path, r->lineno, shown_len(s), s);
    *dt = strtod(at + 9, &end);
    if (end == at + 9)
        return pd_err_set(r->err, PD_EPARSE, "%s:%ld: expected the time step after 'SPACED AT'",
                          r->path, r->lineno);
    return check_npts_dt(r, *npts, *dt);
}

/* What the lines before a V2 file's acceleration block declare. */
typedef struct v2_head {
    int cdmg;             /* the CDMG layout: line 1 "CORRECTED ACCELEROGRAM", line 2
                           * "UNCORRECTED ACCELEROGRAM DATA" */
    long npts, npts_line; /* the text's "N POINTS OF ... DATA" and its line (0: none) */
    double dt;
    long dt_line; /* the text's "INTERVALS OF H SEC" and its line (0: none) */
    double ints[RECORD_V2_INTS], reals[RECORD_V2_REALS]; /* CDMG: the numeric headers */
} v2_head;

#define RECORD_GOT_MAX 72 /* a line shown in a message: 60 characters, quoted */

/* "a blank line" or the line s quoted (its first 60 characters), for messages. */
static const char *v2_got(const char *s, char *buf, size_t cap)
{
    if (line_blank(s))
        snprintf(buf, cap, "a blank line");
    else
        snprintf(buf, cap, "'%.*s'", shown_len(s), s);
    return buf;
}

/* The line of value i (0-based) of a CDMG numeric header starting on line first. */
static long v2_value_line(long first, int i, int cols)
{
    return first + i / cols;
}

/* The n fixed-width fields (width w) of a CDMG numeric header line s into
 * x: integers, or numbers when !integer; a field of '*' (Fortran's
 * overflow) is NaN.  PD_EPARSE when a field is not one, or the line holds
 * more or fewer than n. */
static int v2_fields(const char *s, int n, int w, int integer, double *x)
{
    size_t len = strlen(s), width = (size_t)w;
    while (len > 0 && is_blank((unsigned char)s[len - 1]))
        len--;
    if (len > (size_t)n * width || len <= (size_t)(n - 1) * width || width >= RECORD_WORD_MAX)
        return PD_EPARSE;
    for (int i = 0; i < n; i++) {
        char f[RECORD_WORD_MAX];
        size_t at = (size_t)i * width, m = at + width <= len ? width : len - at;
        memcpy(f, s + at, m);
        f[m] = '\0';
        char *p = f;
        while (*p == ' ')
            p++;
        if (*p && strspn(p, "*") == strlen(p)) {
            x[i] = NAN;
            continue;
        }
        size_t k = number_len(p);
        if (!k || *skip_blanks(p + k) || (integer && strcspn(p, ".eEdD") < k))
            return PD_EPARSE;
        for (size_t j = 0; j < k; j++)
            if (p[j] == 'd' || p[j] == 'D')
                p[j] = 'e';
        x[i] = strtod(p, NULL);
    }
    return PD_OK;
}

/* The current line, of a CDMG numeric header (`what`: "integer" or
 * "real") of count values from line first on, cols of width w to a line:
 * its values into x. */
static int v2_numeric_line(rec_reader *r, const char *what, long first, int count, int cols, int w,
                           int integer, double *x)
{
    long row = r->lineno - first;
    int at = (int)row * cols, n = count - at < cols ? count - at : cols;
    char got[RECORD_GOT_MAX];
    if (v2_fields(r->line, n, w, integer, x + at) == PD_OK)
        return PD_OK;
    return pd_err_set(r->err, PD_EPARSE,
                      "%s:%ld: V2 %s header (lines %ld-%ld of the CDMG layout): expected %d %s "
                      "in columns of %d, got %s",
                      r->path, r->lineno, what, first, first + (count + cols - 1) / cols - 1, n,
                      integer ? "integers" : "numbers", w, v2_got(r->line, got, sizeof got));
}

/* A line that starts a data block: "N POINTS OF X DATA ... SPACED AT H". */
static int v2_data_header(const char *s)
{
    return find_nocase(s, "POINTS OF") && find_nocase(s, "SPACED AT");
}

/* Before the acceleration block: nothing of another block or channel (a
 * lost or damaged acceleration header must not hand over what follows). */
static int v2_boundary(rec_reader *r)
{
    static const char missing[] =
        "before the first channel's acceleration block: its header 'N POINTS OF ACCEL DATA "
        "EQUALLY SPACED AT H SEC' is missing or damaged";
    const char *s = skip_blanks(r->line);
    if (v2_data_header(s)) {
        const char *kind = skip_blanks(find_nocase(s, "POINTS OF") + 9);
        return pd_err_set(r->err, PD_EPARSE, "%s:%ld: a %.*s data block %s", r->path, r->lineno,
                          word_len(kind), kind, missing);
    }
    if (s[0] == '/' && s[1] == '&')
        return pd_err_set(r->err, PD_EPARSE, "%s:%ld: the end of a channel ('/&') %s", r->path,
                          r->lineno, missing);
    if (r->lineno > 1 && find_nocase(s, "CORRECTED ACCELEROGRAM") == s)
        return pd_err_set(r->err, PD_EPARSE, "%s:%ld: a second channel's header %s", r->path,
                          r->lineno, missing);
    return PD_OK;
}

/* A text line's declarations: "N POINTS OF ... DATA" (CDMG's line 16) and
 * "... INTERVALS OF H SEC." (its line 17); the first of each is kept. */
static void v2_declared(rec_reader *r, v2_head *h)
{
    const char *s = skip_blanks(r->line), *at;
    char *end = NULL;
    if (!h->npts_line && find_nocase(s, "POINTS OF")) {
        double n = strtod(s, &end);
        if (end != s && parse_count(n, &h->npts) == PD_OK)
            h->npts_line = r->lineno;
    }
    if (!h->dt_line && (at = find_nocase(s, "INTERVALS OF")) != NULL) {
        h->dt = strtod(at + 12, &end);
        if (end != at + 12)
            h->dt_line = r->lineno;
    }
}

/* The file ended (st 0) or failed (st < 0) before the acceleration block. */
static int v2_header_end(rec_reader *r, const v2_head *h, int st)
{
    if (st < 0)
        return st;
    if (r->lineno == 0)
        return pd_err_set(r->err, PD_EPARSE, "%s:1: empty file: expected a V2 header", r->path);
    if (!h->cdmg)
        return pd_err_set(r->err, PD_EPARSE,
                          "%s:%ld: no V2 acceleration block ('N POINTS OF ACCEL DATA EQUALLY "
                          "SPACED AT H SEC')",
                          r->path, r->lineno);
    const char *where = "ends before the acceleration block header";
    if (r->lineno < RECORD_V2_TEXT_LINES)
        where = "ends in the V2 text header";
    else if (r->lineno < RECORD_V2_TEXT_LINES + RECORD_V2_INT_LINES)
        where = "ends in the V2 integer header";
    else if (r->lineno < RECORD_V2_HEAD_LINES)
        where = "ends in the V2 real header";
    return pd_err_set(r->err, PD_EPARSE,
                      "%s:%ld: the file %s (the CDMG layout: %d text, %d integer and %d real "
                      "lines, the acceleration block header on line %d)",
                      r->path, r->lineno, where, RECORD_V2_TEXT_LINES, RECORD_V2_INT_LINES,
                      RECORD_V2_REAL_LINES, RECORD_V2_HEAD_LINES + 1);
}

/* Read a V2 header up to its first acceleration block's header (then the
 * current line), holding it to its layout: the block within the first
 * channel (v2_boundary); in the CDMG layout, 25 text lines, the integer
 * and real headers in their columns and the block header right after them. */
static int v2_header(rec_reader *r, v2_head *h)
{
    const long ints = RECORD_V2_TEXT_LINES + 1, reals = ints + RECORD_V2_INT_LINES;
    const long block = RECORD_V2_HEAD_LINES + 1;
    char got[RECORD_GOT_MAX];
    int st, line1 = 0;
    while ((st = next_line(r)) == 1) {
        if (find_nocase(r->line, "POINTS OF ACCEL DATA")) {
            if (h->cdmg && r->lineno != block)
                return pd_err_set(r->err, PD_EPARSE,
                                  "%s:%ld: the acceleration block header is on line %ld, but the "
                                  "CDMG V2 header's %ld lines put it on line %ld (%d text, %d "
                                  "integer, %d real: a header line lost or added?)",
                                  r->path, r->lineno, r->lineno, block - 1, block,
                                  RECORD_V2_TEXT_LINES, RECORD_V2_INT_LINES, RECORD_V2_REAL_LINES);
            return PD_OK;
        }
        if ((st = v2_boundary(r)) != PD_OK)
            return st;
        if (r->lineno == 1)
            line1 = find_nocase(r->line, "CORRECTED ACCELEROGRAM") != NULL;
        if (r->lineno == 2)
            h->cdmg = line1 && find_nocase(r->line, "UNCORRECTED ACCELEROGRAM DATA");
        if (h->cdmg && r->lineno >= ints && r->lineno < reals)
            st = v2_numeric_line(r, "integer", ints, RECORD_V2_INTS, RECORD_V2_INT_COLS,
                                 RECORD_V2_INT_WIDTH, 1, h->ints);
        else if (h->cdmg && r->lineno >= reals && r->lineno < block)
            st = v2_numeric_line(r, "real", reals, RECORD_V2_REALS, RECORD_V2_REAL_COLS,
                                 RECORD_V2_REAL_WIDTH, 0, h->reals);
        else if (h->cdmg && r->lineno == block)
            return pd_err_set(r->err, PD_EPARSE,
                              "%s:%ld: expected the acceleration block header 'N POINTS OF "
                              "ACCEL DATA EQUALLY SPACED AT H SEC' after the CDMG V2 header's "
                              "%ld lines (%d text, %d integer, %d real), got %s",
                              r->path, r->lineno, block - 1, RECORD_V2_TEXT_LINES,
                              RECORD_V2_INT_LINES, RECORD_V2_REAL_LINES,
                              v2_got(r->line, got, sizeof got));
        else
            v2_declared(r, h);
        if (st != PD_OK)
            return st;
    }
    return v2_header_end(r, h, st);
}

/* The acceleration block's npts and dt (its header the current line)
 * against what the header declares. */
static int v2_counts(rec_reader *r, const v2_head *h, long npts, double dt)
{
    static const char points[] = "%s:%ld: the acceleration block has %ld points, but the %s "
                                 "header declares %.0f (line %ld)";
    static const char spacing[] = "%s:%ld: the acceleration block is spaced at %g s, but the %s "
                                  "header declares %g s (line %ld)";
    const long ints = RECORD_V2_TEXT_LINES + 1, reals = ints + RECORD_V2_INT_LINES;
    if (h->cdmg) {
        double n = h->ints[RECORD_V2_INT_NPTS], h_dt = h->reals[RECORD_V2_REAL_DT];
        if (n != (double)npts)
            return pd_err_set(r->err, PD_EPARSE, points, r->path, r->lineno, npts, "integer", n,
                              v2_value_line(ints, RECORD_V2_INT_NPTS, RECORD_V2_INT_COLS));
        if (!(fabs(h_dt - dt) <= RECORD_V2_DT_TOL))
            return pd_err_set(r->err, PD_EPARSE, spacing, r->path, r->lineno, dt, "real", h_dt,
                              v2_value_line(reals, RECORD_V2_REAL_DT, RECORD_V2_REAL_COLS));
    }
    if (h->npts_line && h->npts != npts)
        return pd_err_set(r->err, PD_EPARSE, points, r->path, r->lineno, npts, "text",
                          (double)h->npts, h->npts_line);
    if (h->dt_line && !(fabs(h->dt - dt) <= RECORD_V2_DT_TOL))
        return pd_err_set(r->err, PD_EPARSE, spacing, r->path, r->lineno, dt, "text", h->dt,
                          h->dt_line);
    return PD_OK;
}

/* A COSMOS/CDMG V2 file: its first acceleration block, held to what its
 * header declares (v2_header, v2_counts) and its values to the block's
 * points (read_values: as many as declared before the next block). */
static int read_v2(rec_reader *r, rec_buf *b, double *dt)
{
    v2_head h = {.cdmg = 0};
    long npts = 0;
    double scale = 0.01;
    int st = v2_header(r, &h);
    if (st == PD_OK)
        st = v2_npts_dt(r, &npts, dt);
    if (st == PD_OK)
        st = v2_units(r, &scale);
    if (st == PD_OK)
        st = v2_counts(r, &h, npts, *dt);
    if (st == PD_OK)
        st = read_values(r, npts, scale, 1, b);
    if (st == PD_OK)
        st = check_after(r, npts, 1);
    return st;
}

/* ---- two-column text ---------------------------------------------------------- */

/* Ascending order of doubles, for qsort. */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Where a non-uniform time column goes wrong: the first step that differs
 * from the median step by more than a quarter of it (a missing, repeated
 * or misplaced sample), else the first sample off the grid of dt. */
static int text_where(rec_reader *r, const rec_buf *t, const long *lines, double dt)
{
    long n = t->n, k_bad = 0;
    double *steps = malloc((size_t)(n - 1) * sizeof *steps), med = dt;
    if (steps) {
        for (long k = 1; k < n; k++)
            steps[k - 1] = t->v[k] - t->v[k - 1];
        qsort(steps, (size_t)(n - 1), sizeof *steps, cmp_double);
        med = steps[(n - 1) / 2];
        free(steps);
        for (long k = 1; k < n && !k_bad; k++)
            if (fabs(t->v[k] - t->v[k - 1] - med) > 0.25 * med)
                k_bad = k;
    }
    if (k_bad)
        return pd_err_set(r->err, PD_EPARSE,
                          "%s:%ld: non-uniform time column: t = %.9g after %.9g, expected a "
                          "step of %.9g",
                          r->path, lines[k_bad], t->v[k_bad], t->v[k_bad - 1], med);
    for (k_bad = 1; k_bad < n - 1; k_bad++)
        if (fabs(t->v[k_bad] - (t->v[0] + (double)k_bad * dt)) > RECORD_TEXT_TOL * dt)
            break;
    return pd_err_set(r->err, PD_EPARSE,
                      "%s:%ld: non-uniform time column: t = %.9g, expected %.9g (dt = %.9g)",
                      r->path, lines[k_bad], t->v[k_bad], t->v[0] + (double)k_bad * dt, dt);
}

/* t strictly increasing and every t_k within RECORD_TEXT_TOL dt of t_0 +
 * k dt, dt from the end points (the record then starts at t = 0: the
 * first sample is shifted to 0).  A time column rounded to its printed
 * digits passes when half a unit of its last digit is below 1 % of dt
 * (dt = 0.005 s printed to 0.0001 s); a sample that far off its place
 * changes the piecewise-linear record by under 1 % of one step's change. */
static int text_uniform(rec_reader *r, const rec_buf *t, const long *lines, double *dt)
{
    long n = t->n;
    for (long k = 1; k < n; k++)
        if (!(t->v[k] > t->v[k - 1]))
            return pd_err_set(r->err, PD_EPARSE,
                              "%s:%ld: the time column must increase (t = %.9g after %.9g)",
                              r->path, lines[k], t->v[k], t->v[k - 1]);
    double h = (t->v[n - 1] - t->v[0]) / (double)(n - 1);
    for (long k = 1; k < n - 1; k++)
        if (fabs(t->v[k] - (t->v[0] + (double)k * h)) > RECORD_TEXT_TOL * h)
            return text_where(r, t, lines, h);
    *dt = h;
    return check_dt(r, lines[n - 1], h, "the time step");
}

/* Append a line number. */
static int push_line(long **lines, long *cap, long n, long line)
{
    if (n == *cap) {
        long c = *cap ? 2 * *cap : 4096;
        long *grown = realloc(*lines, (size_t)c * sizeof *grown);
        if (!grown)
            return PD_ENOMEM;
        *lines = grown;
        *cap = c;
    }
    (*lines)[n] = line;
    return PD_OK;
}

/* One data line "t a" (comment cut): 1 with both, 0 blank, or an error. */
static int text_pair(rec_reader *r, double *t, double *a)
{
    char *hash = strchr(r->line, '#');
    if (hash)
        *hash = '\0';
    const char *p = r->line;
    double extra;
    int st = scan_number(r, &p, t);
    if (st <= 0)
        return st;
    if ((st = scan_number(r, &p, a)) < 0)
        return st;
    if (st == 0 || (st = scan_number(r, &p, &extra)) != 0)
        return st < 0
                   ? st
                   : pd_err_set(r->err, PD_EPARSE, "%s:%ld: expected two numbers 't a' on a line",
                                r->path, r->lineno);
    return 1;
}

/* A two-column text file: accelerations into b, times checked. */
static int read_text(rec_reader *r, double scale, rec_buf *b, double *dt)
{
    rec_buf t = {0};
    long *lines = NULL, lcap = 0;
    int st;
    while ((st = next_line(r)) == 1) {
        double tk, ak;
        if ((st = text_pair(r, &tk, &ak)) < 0)
            break;
        if (st == 0)
            continue;
        if (t.n > 0 && !(tk > t.v[t.n - 1])) { /* at once: not after 10^8 samples */
            st = pd_err_set(r->err, PD_EPARSE,
                            "%s:%ld: the time column must increase (t = %.9g after %.9g)", r->path,
                            r->lineno, tk, t.v[t.n - 1]);
            break;
        }
        if ((st = finite_si(r, ak, scale)) != PD_OK)
            break;
        if (t.n >= RECORD_NPTS_MAX) {
            st = pd_err_set(r->err, PD_EPARSE, "%s:%ld: more samples than the %ld read", r->path,
                            r->lineno, RECORD_NPTS_MAX);
            break;
        }
        if (buf_push(&t, tk, RECORD_NPTS_MAX) || buf_push(b, scale * ak, RECORD_NPTS_MAX) ||
            push_line(&lines, &lcap, t.n - 1, r->lineno)) {
            st = pd_err_set(r->err, PD_ENOMEM, "%s: out of memory", r->path);
            break;
        }
    }
    if (st == 0 && t.n < 2)
        st = pd_err_set(r->err, PD_EPARSE,
                        t.n ? "%s:%ld: one sample: expected at least 2 lines 't a'"
                            : "%s:%ld: no data: expected lines 't a'",
                        r->path, r->lineno ? r->lineno : 1);
    if (st == 0)
        st = text_uniform(r, &t, lines, dt);
    free(t.v);
    free(lines);
    return st;
}

/* ---- dispatch -------------------------------------------------------------------- */

/* The format named by the first lines: an NPTS line (AT2), an acceleration
 * block header (V2), else by the file name's extension, else text. */
static int detect_format(rec_reader *r, pd_record_format *f)
{
    int st;
    *f = PD_RECORD_TEXT;
    while ((st = next_line(r)) == 1 && r->lineno <= RECORD_V2_HEAD) {
        if (r->lineno <= RECORD_AT2_HEAD && find_nocase(r->line, "NPTS") &&
            find_nocase(r->line, "DT")) {
            *f = PD_RECORD_AT2;
            break;
        }
        if (find_nocase(r->line, "POINTS OF ACCEL DATA") ||
            (r->lineno == 1 && find_nocase(r->line, "CORRECTED ACCELEROGRAM"))) {
            *f = PD_RECORD_V2;
            break;
        }
    }
    if (st < 0)
        return st;
    if (*f == PD_RECORD_TEXT) {
        const char *dot = strrchr(r->path, '.');
        if (dot && !strchr(dot, '/') && find_nocase(dot, ".at2") == dot && !dot[4])
            *f = PD_RECORD_AT2;
        else if (dot && !strchr(dot, '/') && find_nocase(dot, ".v2") == dot && !dot[3])
            *f = PD_RECORD_V2;
    }
    if (r->lineno == 0 && st == 0)
        return pd_err_set(r->err, PD_EPARSE, "%s:1: empty file: expected a record", r->path);
    return reader_rewind(r);
}

/* The file's name without its folders. */
static void set_name(pd_record *rec, const char *path)
{
    const char *slash = strrchr(path, '/');
    snprintf(rec->name, sizeof rec->name, "%s", slash ? slash + 1 : path);
}

int pd_record_detect(const char *path, pd_record_format *format, pd_err *err)
{
    if (!path || !format)
        return PD_NULL_ARG(err, !path ? "path" : "format");
    rec_reader r;
    int st = reader_open(&r, path, err);
    if (st == PD_OK)
        st = detect_format(&r, format);
    reader_close(&r);
    return st;
}

/* The plausible peak ground accelerations, in g. */
#define RECORD_PGA_MIN_G 1e-4
#define RECORD_PGA_MAX_G 5.0

int pd_record_plausible(const pd_record *rec, pd_record_units units, char *msg, size_t cap)
{
    if (!rec || !rec->acc || rec->npts < 1)
        return 0;
    double pga = 0.0;
    for (long k = 0; k < rec->npts; k++)
        pga = fmax(pga, fabs(rec->acc[k]));
    double g = pga / PD_G_STANDARD, s = units_scale(units);
    if (g >= RECORD_PGA_MIN_G && g <= RECORD_PGA_MAX_G)
        return 1;
    /* the units the same numbers would be plausible in */
    const pd_record_units all[] = {PD_UNITS_G, PD_UNITS_M_S2, PD_UNITS_CM_S2};
    const char *fix = NULL;
    for (int i = 0; i < 3; i++) {
        double gi = pga / s * units_scale(all[i]) / PD_G_STANDARD;
        if (all[i] != units && gi >= RECORD_PGA_MIN_G && gi <= RECORD_PGA_MAX_G) {
            fix = pd_record_units_name(all[i]);
            break;
        }
    }
    if (msg && cap > 0)
        snprintf(msg, cap,
                 "%s: its peak ground acceleration is %.3g g read in %s, %s than %g "
                 "g%s%s%s",
                 rec->name, g, pd_record_units_name(units), g > RECORD_PGA_MAX_G ? "more" : "less",
                 g > RECORD_PGA_MAX_G ? RECORD_PGA_MAX_G : RECORD_PGA_MIN_G,
                 fix ? ": are its values in " : "", fix ? fix : "", fix ? "? (--units)" : "");
    return 0;
}

int pd_record_from_array(pd_record *rec, const char *name, const double *acc, long npts, double dt,
                         pd_record_units units, pd_err *err)
{
    if (!rec || !acc)
        return PD_NULL_ARG(err, !rec ? "rec" : "acc");
    *rec = (pd_record){.npts = 0};
    if (npts < 2 || npts > RECORD_NPTS_MAX)
        return pd_err_set(err, PD_EINVAL, "record: %ld samples (expected 2 to %ld)", npts,
                          RECORD_NPTS_MAX);
    if (!(dt >= PD_RECORD_DT_MIN && dt <= PD_RECORD_DT_MAX))
        return pd_err_set(err, PD_EINVAL,
                          "record_dt: %g s: expected a sampling interval in [%g, %g] s", dt,
                          PD_RECORD_DT_MIN, PD_RECORD_DT_MAX);
    if (units != PD_UNITS_G && units != PD_UNITS_M_S2 && units != PD_UNITS_CM_S2)
        return pd_err_set(err, PD_EINVAL, "units: unknown units %d", (int)units);
    double s = units_scale(units);
    for (long k = 0; k < npts; k++)
        if (!isfinite(s * acc[k]))
            return pd_err_set(err, PD_EINVAL,
                              "record: sample %ld is %g %s (not a finite "
                              "acceleration)",
                              k, acc[k], pd_record_units_name(units));
    double *v = malloc((size_t)npts * sizeof(double));
    if (!v)
        return pd_err_set(err, PD_ENOMEM, "record: out of memory for %ld samples", npts);
    for (long k = 0; k < npts; k++)
        v[k] = s * acc[k]; /* as the readers: the unit times the value */
    snprintf(rec->name, sizeof rec->name, "%s", name ? name : "array");
    rec->npts = npts;
    rec->dt = dt;
    rec->acc = v;
    pd_err_clear(err);
    return PD_OK;
}

int pd_record_read(const char *path, pd_record_format format, pd_record_units units, pd_record *rec,
                   pd_err *err)
{
    if (!path || !rec)
        return PD_NULL_ARG(err, !path ? "path" : "rec");
    *rec = (pd_record){.npts = 0};
    rec_reader r;
    rec_buf b = {0};
    double dt = 0.0;
    int st = reader_open(&r, path, err);
    if (st == PD_OK && format == PD_RECORD_AUTO)
        st = detect_format(&r, &format);
    if (st == PD_OK) {
        switch (format) {
        case PD_RECORD_AT2:
            st = read_at2(&r, &b, &dt);
            break;
        case PD_RECORD_V2:
            st = read_v2(&r, &b, &dt);
            break;
        case PD_RECORD_TEXT:
            st = read_text(&r, units_scale(units), &b, &dt);
            break;
        default:
            st = pd_err_set(err, PD_EINVAL, "%s: unknown record format %d", path, format);
        }
    }
    reader_close(&r);
    if (st != PD_OK) {
        free(b.v);
        return st;
    }
    set_name(rec, path);
    rec->npts = b.n;
    rec->dt = dt;
    rec->acc = b.v;
    pd_err_clear(err);
    return PD_OK;
}
