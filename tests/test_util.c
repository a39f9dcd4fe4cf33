/* test_util.c — helpers the CLI suites share: running pound and capturing
 * its output, reading JSON members, scratch folders, HDF5 attributes. */
#include <dirent.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "pd_test.h"

/* Read a whole file into a malloc'd NUL-terminated buffer. */
char *pd_test_slurp(const char *path)
{
    FILE *f = fopen(path, "rb");
    size_t n = 0, cap = 4096;
    char *buf = malloc(cap);
    while (f && buf) {
        if (n + 1 >= cap) {
            char *b = realloc(buf, cap *= 2);
            if (!b)
                break;
            buf = b;
        }
        size_t r = fread(buf + n, 1, cap - n - 1, f);
        if (r == 0)
            break;
        n += r;
    }
    if (buf)
        buf[n] = '\0';
    if (f)
        fclose(f);
    return buf;
}

/* Release what spawn captured. */
void pd_test_proc_free(proc_out *r)
{
    free(r->out);
    free(r->err);
    r->out = r->err = NULL;
}

/* Run argv (argv[0] a path or a name on PATH) with env ("NAME=value" or
 * NULL) added, capturing stdout and stderr; returns the exit status. */
int pd_test_spawn(const char *const *argv, const char *env, proc_out *r)
{
    char out_path[] = "/tmp/pd_spec_outXXXXXX", err_path[] = "/tmp/pd_spec_errXXXXXX";
    int fo = mkstemp(out_path), fe = mkstemp(err_path), st = 0;
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        dup2(fo, 1);
        dup2(fe, 2);
        if (env) {
            char kv[256];
            snprintf(kv, sizeof kv, "%s", env);
            char *eq = strchr(kv, '=');
            if (eq) {
                *eq = '\0';
                setenv(kv, eq + 1, 1);
            }
        }
        execvp(argv[0], (char *const *)argv);
        _exit(127);
    }
    waitpid(pid, &st, 0);
    close(fo);
    close(fe);
    r->out = pd_test_slurp(out_path);
    r->err = pd_test_slurp(err_path);
    unlink(out_path);
    unlink(err_path);
    r->status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    return r->status;
}

/* Run `pound spectrum` (or another subcommand) with args, NULL-terminated. */
int pd_test_pound(const pd_test_ctx *ctx, const char *const *args, proc_out *r)
{
    const char *argv[80];
    int n = 0;
    argv[n++] = ctx->pound;
    for (; args[n - 1] && n < 79; n++)
        argv[n] = args[n - 1];
    argv[n] = NULL;
    return pd_test_spawn(argv, NULL, r);
}

/* Is the binary under test there?  Skips the case otherwise. */
int pd_test_have_pound(pd_test_ctx *ctx)
{
    if (access(ctx->pound, X_OK) == 0)
        return 1;
    pd_test_skip(ctx, "no pound binary (pass --pound PATH)");
    return 0;
}

/* The number after the k-th "key": (NAN when absent or null). */
double pd_test_json_num(const char *json, const char *key, int k)
{
    char pat[64];
    const char *p = json;
    snprintf(pat, sizeof pat, "\"%s\":", key);
    for (int i = 0; p && i <= k; i++)
        if ((p = strstr(p, pat)))
            p += strlen(pat);
    if (!p || !strncmp(p, "null", 4))
        return NAN;
    return strtod(p, NULL);
}

/* The string after the k-th "key": into buf ("" when absent). */
void pd_test_json_str(const char *json, const char *key, int k, char *buf, size_t cap)
{
    char pat[64];
    const char *p = json;
    snprintf(pat, sizeof pat, "\"%s\":\"", key);
    for (int i = 0; p && i <= k; i++)
        if ((p = strstr(p, pat)))
            p += strlen(pat);
    size_t n = p ? strcspn(p, "\"") : 0;
    n = n < cap ? n : cap - 1;
    memcpy(buf, p ? p : "", n);
    buf[n] = '\0';
}

/* Number of entries in a directory besides . and .. */
int pd_test_dir_entries(const char *dir)
{
    DIR *d = opendir(dir);
    int n = 0;
    for (struct dirent *e; d && (e = readdir(d));)
        n += strcmp(e->d_name, ".") && strcmp(e->d_name, "..");
    if (d)
        closedir(d);
    return n;
}

/* Remove a scratch directory and its files. */
void pd_test_rm_dir(const char *dir)
{
    DIR *d = opendir(dir);
    char path[1024];
    for (struct dirent *e; d && (e = readdir(d));)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
            snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
            unlink(path);
        }
    if (d)
        closedir(d);
    rmdir(dir);
}

/* Are two files byte-identical (and both present)? */
int pd_test_same_file(const char *a, const char *b)
{
    FILE *f = fopen(a, "rb"), *g = fopen(b, "rb");
    int same = f && g, x = 0, y = 0;
    while (same && (x = fgetc(f)) == (y = fgetc(g)) && x != EOF)
        ;
    same = same && x == y;
    if (f)
        fclose(f);
    if (g)
        fclose(g);
    return same;
}

/* A double attribute (NAN when missing). */
double pd_test_h5_num(hid_t obj, const char *name)
{
    double x = NAN;
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    if (a >= 0) {
        H5Aread(a, H5T_NATIVE_DOUBLE, &x);
        H5Aclose(a);
    }
    return x;
}

pd_run_opts pd_test_pen(const pd_run_opts *base, const pd_penalty_setup *po)
{
    pd_run_opts o = base ? *base : pd_run_default_opts();
    pd_run_opts d = pd_run_default_opts();
    o.method = PD_METHOD_PENALTY;
    o.pen = *po;
    o.pen.rtol = po->rtol != 0.0 ? po->rtol : d.pen.rtol;
    o.pen.atol = po->atol != 0.0 ? po->atol : d.pen.atol;
    o.pen.stepper = po->stepper ? po->stepper : d.pen.stepper;
    return o;
}

double pd_test_uniform(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull); /* splitmix64 */
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1.0p-53;
}

int pd_test_zero_file(char *path, size_t cap, long long bytes)
{
    snprintf(path, cap, "/tmp/pd_zeroXXXXXX");
    int fd = mkstemp(path);
    if (fd < 0)
        return -1;
    int rc = ftruncate(fd, (off_t)bytes);
    close(fd);
    if (rc)
        unlink(path);
    return rc;
}

int pd_test_yield_pulse_case(int c, pd_sine_piece pc[2], pd_ed_sdof *p, char *name, size_t cap)
{
    const double pi2s[] = {0.7, 1.5}, eps[] = {0.0, 0.5, 1.0}, alphas[] = {0.0, 0.1, 0.3},
                 uys[] = {0.05, 0.3};
    int n = 0;
    for (int pulse = 0; pulse < 2; pulse++)
        for (int i = 0; i < 2; i++)
            for (int k = 0; k < 3; k++)
                for (int a = 0; a < 3; a++)
                    for (int u = 0; u < 2; u++)
                        for (int wall = 0; wall < 2; wall++) {
                            if ((!wall && k > 0) || n++ != c) /* eps: nothing without the wall */
                                continue;
                            pc[0] = (pd_sine_piece){.t_start = 0.0,
                                                    .A = -1.0,
                                                    .w = 1.0,
                                                    .phi = pulse ? PD_PI / 2 : 0.0};
                            pc[1] = (pd_sine_piece){.t_start = 2.0 * PD_PI};
                            *p = (pd_ed_sdof){.osc = {.w0 = 1.0 / pi2s[i], .xi = 0.05},
                                              .wall = wall,
                                              .delta = 0.1,
                                              .e = eps[k],
                                              .npieces = 2,
                                              .pieces = pc,
                                              .uy = uys[u],
                                              .alpha = alphas[a]};
                            snprintf(name, cap, "%s Pi2 %g eps %g alpha %g uy %g wall %d",
                                     pulse ? "cosine" : "sine", pi2s[i], eps[k], alphas[a], uys[u],
                                     wall);
                            return 1;
                        }
    return 0;
}

pd_scene *pd_test_yield_row(pd_test_ctx *ctx, int n, double dgap)
{
    pd_scene_excitation x = {.pulse = PD_PULSE_SINE, .dir = 1, .ap = 4.0, .Tp = 0.8};
    pd_scene *sc = pd_scene_new(&x);
    pd_err e;
    int rc = sc ? PD_OK : PD_ENOMEM;
    for (int i = 0; i < n && !rc; i++) {
        char name[16];
        double uy = 0.01 + 0.001 * (i % 10), alpha = 0.02 * (i % 10);
        snprintf(name, sizeof name, "S%d", i + 1);
        rc = pd_scene_add_sdof(sc, name, 0.4 + 0.1 * (i % 10), 0.05, 1e5, &e) ||
             pd_scene_set_yield(sc, &uy, &alpha, &e);
    }
    for (int i = 0; i <= n && !rc; i++)
        rc =
            pd_scene_add_contact(sc, i == 0 ? PD_WALL : i - 1, i == 0 ? 0 : 1, i == n ? PD_WALL : i,
                                 i == n ? 0 : 1, 0.03 + dgap * (i % 7), 0.6, i, &e);
    if (!rc)
        rc = pd_scene_finish(sc, &e);
    if (!CHECK(ctx, rc == PD_OK, "the row: %s", sc ? e.msg : "out of memory")) {
        pd_scene_free(sc);
        return NULL;
    }
    sc->tend = 3.0;
    return sc;
}

int pd_test_scene_run(pd_test_ctx *ctx, const pd_scene *sc, pd_method method, double dt,
                      pd_scene_result *r)
{
    pd_run_opts o = pd_run_default_opts();
    o.method = method;
    o.dt = dt;
    pd_err e;
    int rc = pd_scene_result_alloc(sc, r, &e);
    if (!rc)
        rc = pd_scene_run(sc, &o, NULL, NULL, r, &e);
    return CHECK(ctx, rc == PD_OK, "%s dt %g: %s", pd_method_name(method), dt, e.msg);
}

pd_sine_piece *pd_test_rinaldi_pieces(pd_test_ctx *ctx, long *npieces)
{
    pd_record rec;
    pd_osc c;
    if (!pd_test_rinaldi_case(ctx, &rec, &c))
        return NULL;
    long np = rec.npts;
    pd_sine_piece *pc = calloc((size_t)np, sizeof *pc);
    if (CHECK(ctx, pc != NULL, "out of memory")) {
        for (long k = 0; k + 1 < np; k++) /* F = -a_g, linear between samples */
            pc[k] = (pd_sine_piece){.t_start = (double)k * rec.dt,
                                    .c0 = -rec.acc[k],
                                    .c1 = -(rec.acc[k + 1] - rec.acc[k]) / rec.dt};
        pc[np - 1] = (pd_sine_piece){.t_start = (double)(np - 1) * rec.dt};
        *npieces = np;
    }
    pd_record_free(&rec);
    return pc;
}

int pd_test_rinaldi_case(pd_test_ctx *ctx, pd_record *rec, pd_osc *c)
{
    const char *path = "examples/records/NGA_no_1063_RRS228.AT2";
    pd_record_pulse p;
    pd_err err;
    if (access(path, R_OK)) {
        pd_test_skip(ctx, "the Rinaldi record is absent");
        return 0;
    }
    if (!CHECK(ctx, pd_record_read(path, PD_RECORD_AUTO, PD_UNITS_G, rec, &err) == PD_OK, "%s",
               err.msg))
        return 0;
    if (!CHECK(ctx, pd_record_fit_pulse(rec, &p, &err) == PD_OK, "%s", err.msg)) {
        pd_record_free(rec);
        return 0;
    }
    *c = pd_osc_default();
    pd_osc_set_record(c, rec, &p, 1.0);
    pd_osc_set_T0(c, 0.8);
    pd_osc_set_gap(c, 0.01);
    c->eps = 0.6;
    return 1;
}

/* The scene of a JSON text written to path and loaded (NULL: named; the
 * file is removed then). */
pd_scene *pd_test_scene_of_text(pd_test_ctx *ctx, const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!CHECK(ctx, f != NULL, "cannot write %s", path))
        return NULL;
    fputs(text, f);
    fclose(f);
    pd_scene *sc = NULL;
    pd_err e;
    if (!CHECK(ctx, pd_scene_load(path, &sc, &e) == PD_OK, "%s", e.msg)) {
        remove(path);
        return NULL;
    }
    return sc;
}
