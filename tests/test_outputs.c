/* test_outputs.c — the output side of pound (issue 11): full disks
 * (RLIMIT_FSIZE in the child), write errors on standard output, bounded
 * memory for long histories, signals and stale temporary files, unwritable
 * targets found before the run, modes and symlinks kept, spectrum journals. */
#define _DEFAULT_SOURCE /* wait4: a child's own peak memory */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "pd_test.h"

#if defined(__SANITIZE_ADDRESS__)
#define PD_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PD_TEST_ASAN 1
#endif
#endif

/* ---- running pound in a child with limits -------------------------------- */

/* How the child runs. */
typedef struct child_opts {
    long fsize;            /* RLIMIT_FSIZE in bytes (0: no limit); SIGXFSZ left at its
                              default, as users run it: pound must ignore it itself */
    const char *stdout_to; /* standard output into this file (NULL: captured) */
} child_opts;

/* A started child and where its output goes. */
typedef struct child {
    pid_t pid;
    char out[32], err[32];
} child;

/* Start pound with args (NULL-terminated): 0, or -1. */
static int child_start(const pd_test_ctx *ctx, const char *const *args, const child_opts *o,
                       child *c)
{
    const char *argv[64];
    int n = 0;
    argv[n++] = ctx->pound;
    while (args[n - 1] && n < 63) {
        argv[n] = args[n - 1];
        n++;
    }
    argv[n] = NULL;
    snprintf(c->out, sizeof c->out, "/tmp/pd_out_oXXXXXX");
    snprintf(c->err, sizeof c->err, "/tmp/pd_out_eXXXXXX");
    int fo = mkstemp(c->out), fe = mkstemp(c->err);
    fflush(stdout);
    c->pid = fo >= 0 && fe >= 0 ? fork() : -1;
    if (c->pid == 0) {
        int to = o && o->stdout_to ? open(o->stdout_to, O_WRONLY) : fo;
        dup2(to >= 0 ? to : fo, 1);
        dup2(fe, 2);
        umask(022);
        signal(SIGINT, SIG_DFL); /* a background test run may ignore it */
        signal(SIGTERM, SIG_DFL);
        if (o && o->fsize > 0) {
            struct rlimit rl = {.rlim_cur = (rlim_t)o->fsize, .rlim_max = (rlim_t)o->fsize};
            signal(SIGXFSZ, SIG_DFL);
            setrlimit(RLIMIT_FSIZE, &rl);
        }
        execv(argv[0], (char *const *)argv);
        _exit(127);
    }
    if (fo >= 0)
        close(fo);
    if (fe >= 0)
        close(fe);
    return c->pid > 0 ? 0 : -1;
}

/* Wait for the child: its exit status, or 128 + the signal that ended it;
 * what it printed into r; its resource use into ru (may be NULL). */
static int child_wait(child *c, proc_out *r, struct rusage *ru)
{
    int st = 0;
    struct rusage use;
    pid_t w = c->pid > 0 ? wait4(c->pid, &st, 0, &use) : -1;
    r->out = pd_test_slurp(c->out);
    r->err = pd_test_slurp(c->err);
    unlink(c->out);
    unlink(c->err);
    if (ru)
        *ru = use;
    r->status = w < 0 ? -1 : WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
    return r->status;
}

/* Run pound to the end. */
static int run(const pd_test_ctx *ctx, const char *const *args, const child_opts *o, proc_out *r,
               struct rusage *ru)
{
    child c;
    if (child_start(ctx, args, o, &c)) {
        r->out = calloc(1, 1);
        r->err = calloc(1, 1);
        return r->status = -1;
    }
    return child_wait(&c, r, ru);
}

/* ---- scratch folders and files ------------------------------------------- */

/* A scratch folder /tmp/pd_out_NAME_XXXXXX into dir: 0 or -1. */
static int scratch(pd_test_ctx *ctx, const char *name, char *dir, size_t cap)
{
    snprintf(dir, cap, "/tmp/pd_out_%s_XXXXXX", name);
    return CHECK(ctx, mkdtemp(dir) != NULL, "mkdtemp %s", dir) ? 0 : -1;
}

/* dir/name into buf. */
static const char *in(const char *dir, const char *name, char *buf, size_t cap)
{
    snprintf(buf, cap, "%s/%s", dir, name);
    return buf;
}

/* Does a file (or a link) exist? */
static int exists(const char *path)
{
    struct stat st;
    return lstat(path, &st) == 0;
}

/* Number of entries of dir whose name starts with prefix. */
static int entries_with(const char *dir, const char *prefix)
{
    DIR *d = opendir(dir);
    int n = 0;
    for (struct dirent *e; d && (e = readdir(d));)
        n += !strncmp(e->d_name, prefix, strlen(prefix));
    if (d)
        closedir(d);
    return n;
}

/* Write text into path: 0 or -1. */
static int write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    int ok = f && fputs(text, f) >= 0;
    return f && fclose(f) == 0 && ok ? 0 : -1;
}

/* One line on stderr? */
static int one_line(const char *s)
{
    const char *nl = s ? strchr(s, '\n') : NULL;
    return nl && nl[1] == '\0';
}

/* Sleep ms milliseconds. */
static void sleep_ms(long ms)
{
    struct timespec t = {.tv_sec = ms / 1000, .tv_nsec = (ms % 1000) * 1000000L};
    nanosleep(&t, NULL);
}

/* Seconds of wall time. */
static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* A small scene: two SDOFs and a wall. */
static const char two_sdof[] =
    "{\"excitation\": {\"pulse\": \"sine\", \"dir\": \"+x\", \"ap\": 4.0, \"Tp\": 0.3},\n"
    " \"structures\": [{\"name\": \"A\", \"T0\": 0.5}, {\"name\": \"B\", \"T0\": 1.0}],\n"
    " \"contacts\": [{\"a\": \"A\", \"b\": \"B\", \"gap\": 0.01, \"eps\": 0.5},\n"
    "              {\"a\": \"B\", \"b\": \"wall\", \"gap\": 0.02, \"eps\": 0.5}],\n"
    " \"tend\": 2.0}\n";

/* ---- 1. full disks --------------------------------------------------------- */

/* A run under a file-size limit failed as it must: exit 1 (not a signal),
 * its one line (msg_ok), nothing left in dir. */
static void expect_too_large(pd_test_ctx *ctx, const proc_out *r, const char *name, long limit,
                             int msg_ok, const char *dir)
{
    CHECK(ctx, r->status == 1, "%s at %ld bytes: exit %d (128+11 is SIGSEGV): %s", name, limit,
          r->status, r->err);
    CHECK(ctx, msg_ok, "%s at %ld bytes: one line naming the file and the reason: %s", name, limit,
          r->err);
    CHECK(ctx, pd_test_dir_entries(dir) == 0, "%s at %ld bytes: %d files left", name, limit,
          pd_test_dir_entries(dir));
}

/* The next case in an empty scratch folder. */
static void next_case(proc_out *r, const char *dir)
{
    pd_test_proc_free(r);
    pd_test_rm_dir(dir);
    mkdir(dir, 0700);
}

/* Under a file-size limit (a full disk without root), simulate -o F.h5 /
 * F.csv and a scene with --dump-lcp, at limits that fail at the start,
 * during the run and in the last flush (the 1.65 MB HDF5 file at 1.6 MB):
 * exit 1 (never a crash in HDF5's exit cleanup, never exit 0 with zeros),
 * one line naming the file with the system's reason, no file left. */
static void test_outputs_full_disk_simulate(pd_test_ctx *ctx)
{
    static const struct {
        const char *name;
        long limit;
    } cases[] = {
        {"x.h5", 2048}, {"x.h5", 1600000}, {"x.csv", 65536}, {"s.h5", 65536}, {"s.csv", 65536}};
    char dir[64], out[128], scene[128], dump[128];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "disk", dir, sizeof dir))
        return;
    in(dir, "scene.json", scene, sizeof scene);
    in(dir, "d.h5", dump, sizeof dump);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        proc_out r;
        child_opts o = {.fsize = cases[k].limit};
        int is_scene = cases[k].name[0] == 's';
        in(dir, cases[k].name, out, sizeof out);
        const char *osc[] = {"simulate", "--Tp",  "0.3",   "--T0", "3",  "--ap", "4",
                             "--gap",    "0.004", "--eps", "0.6",  "-o", out,    NULL};
        const char *sc[] = {"simulate", "--scene", scene,        "--dt", "2e-5",
                            "-o",       out,       "--dump-lcp", dump,   NULL};
        if (is_scene && !CHECK(ctx, write_file(scene, two_sdof) == 0, "the scene file"))
            break;
        run(ctx, is_scene ? sc : osc, &o, &r, NULL);
        unlink(scene);
        expect_too_large(ctx, &r, cases[k].name, cases[k].limit,
                         strstr(r.err, "File too large") && strstr(r.err, out) && one_line(r.err),
                         dir);
        next_case(&r, dir);
    }
    pd_test_rm_dir(dir);
}

/* spectrum -o F.h5 / F.csv under a file-size limit: exit 1 with the reason,
 * no F and no temporary file; the journal stays for --resume. */
static void test_outputs_full_disk_spectrum(pd_test_ctx *ctx)
{
    static const char *const names[] = {"s.h5", "s.csv"};
    char dir[64], out[128], journal[160];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "sdisk", dir, sizeof dir))
        return;
    for (int k = 0; k < 2; k++) {
        proc_out r;
        child_opts o = {.fsize = 4096};
        in(dir, names[k], out, sizeof out);
        snprintf(journal, sizeof journal, "%s.partial", out);
        const char *args[] = {"spectrum", "--Pi2", "0.5:2:12", "--Pi3",
                              "0.05,0.1", "-o",    out,        NULL};
        run(ctx, args, &o, &r, NULL);
        CHECK(ctx, r.status == 1, "%s: exit %d (128+11 is SIGSEGV): %s", names[k], r.status, r.err);
        CHECK(ctx, r.err && strstr(r.err, "File too large") && one_line(r.err),
              "%s: one line with the reason: %s", names[k], r.err);
        CHECK(ctx, !exists(out) && exists(journal) && pd_test_dir_entries(dir) == 1,
              "%s: expected only the journal, %d files", names[k], pd_test_dir_entries(dir));
        unlink(journal);
        pd_test_proc_free(&r);
    }
    pd_test_rm_dir(dir);
}

/* ---- 2. standard output -------------------------------------------------- */

/* Output to /dev/full: exit 1 and "pound: standard output: No space left on
 * device" (lcp --json, simulate text, a usage page). */
static void test_outputs_stdout_write_error(pd_test_ctx *ctx)
{
    char dir[64], lcp[128];
    if (!pd_test_have_pound(ctx))
        return;
    if (access("/dev/full", W_OK) != 0) {
        pd_test_skip(ctx, "no /dev/full");
        return;
    }
    if (scratch(ctx, "full", dir, sizeof dir))
        return;
    in(dir, "f.lcp", lcp, sizeof lcp);
    write_file(lcp, "2\n2 1\n1 2\n-1 -1\n");
    const char *a_lcp[] = {"lcp", lcp, "--json", NULL};
    const char *a_sim[] = {"simulate", "--Tp", "0.3", "--T0", "0.5", NULL};
    const char *a_help[] = {"simulate", "--help", NULL};
    const char *const *cases[] = {a_lcp, a_sim, a_help};
    for (int k = 0; k < 3; k++) {
        proc_out r;
        child_opts o = {.stdout_to = "/dev/full"};
        run(ctx, cases[k], &o, &r, NULL);
        CHECK(ctx, r.status == 1, "%s > /dev/full: exit %d", cases[k][0], r.status);
        CHECK(ctx, r.err && !strcmp(r.err, "pound: standard output: No space left on device\n"),
              "%s > /dev/full: stderr '%s'", cases[k][0], r.err);
        pd_test_proc_free(&r);
    }
    pd_test_rm_dir(dir);
}

/* ---- 3. bounded memory, the same content ------------------------------------ */

/* A 2.6e6-step history (104 MB to write; its buffer was 104 MB of memory)
 * needs no more memory than a 2e5-step one, and the run announces the
 * size first; skipped under AddressSanitizer (its quarantine grows RSS). */
static void test_outputs_memory_bounded(pd_test_ctx *ctx)
{
#ifdef PD_TEST_ASAN
    pd_test_skip(ctx, "AddressSanitizer: resident memory is not the program's");
    return;
#endif
    char dir[64], out[128];
    long rss[2];
    static const char *const tends[] = {"0.2", "2.6"};
    if (!pd_test_have_pound(ctx) || scratch(ctx, "mem", dir, sizeof dir))
        return;
    in(dir, "big.h5", out, sizeof out);
    for (int k = 0; k < 2; k++) {
        proc_out r;
        struct rusage ru;
        const char *args[] = {"simulate", "--Tp",   "0.3",    "--T0",  "3",   "--ap",
                              "4",        "--gap",  "0.004",  "--eps", "0.6", "--dt",
                              "1e-6",     "--tend", tends[k], "-o",    out,   NULL};
        run(ctx, args, NULL, &r, &ru);
        rss[k] = ru.ru_maxrss; /* kB */
        CHECK(ctx, r.status == 0, "tend %s: exit %d: %s", tends[k], r.status, r.err);
        if (k == 1)
            CHECK(ctx, r.err && strstr(r.err, "pound: writing about 104 MB to ") && one_line(r.err),
                  "the size announced: '%s'", r.err);
        pd_test_proc_free(&r);
        unlink(out);
    }
    CHECK(ctx, rss[1] - rss[0] < 20000, "peak memory %ld kB for 2.6e6 steps vs %ld kB for 2e5",
          rss[1], rss[0]);
    pd_test_rm_dir(dir);
}

/* The samples of a run, collected in the test. */
typedef struct samples {
    long n, cap, every;
    double *v; /* n rows of t, u, v, impulse, gap */
} samples;

static int collect(const pd_osc_sample *s, void *ctx)
{
    samples *c = ctx;
    if (s->step % c->every || c->n >= c->cap)
        return 0;
    double row[5] = {s->t, s->u, s->v, s->impulse, s->gap};
    memcpy(c->v + 5 * c->n++, row, sizeof row);
    return 0;
}

/* A whole 1-D double dataset (NULL when missing); its length in *n. */
static double *read_dataset(hid_t f, const char *name, long *n)
{
    hid_t ds = H5Dopen2(f, name, H5P_DEFAULT);
    hsize_t dims[1] = {0};
    double *x = NULL;
    *n = -1;
    if (ds < 0)
        return NULL;
    hid_t sp = H5Dget_space(ds);
    if (sp >= 0 && H5Sget_simple_extent_ndims(sp) == 1 &&
        H5Sget_simple_extent_dims(sp, dims, NULL) == 1 && (x = malloc((dims[0] + 1) * sizeof *x)) &&
        H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, x) >= 0)
        *n = (long)dims[0];
    if (sp >= 0)
        H5Sclose(sp);
    H5Dclose(ds);
    return x;
}

/* The streamed oscillator files hold exactly what the run sampled: every
 * value of t, u, v, impulse and gap in the HDF5 datasets and the CSV rows
 * equals the library's own samples (every 3rd step), and the summary
 * attributes match. */
static void test_outputs_content_unchanged(pd_test_ctx *ctx)
{
    static const char *const cols[] = {"t", "u", "v", "impulse", "gap"};
    char dir[64], h5[128], csv[128];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "same", dir, sizeof dir))
        return;
    in(dir, "run.h5", h5, sizeof h5);
    in(dir, "run.csv", csv, sizeof csv);
    pd_osc c = pd_osc_default();
    c.ap = 4.0;
    c.Tp = 0.3;
    c.Pi2 = 0.1;
    c.Pi3 = 0.4;
    c.eps = 0.6;
    pd_run_opts o = pd_run_default_opts();
    o.method = PD_METHOD_MOREAU; /* as the command's --dt chooses */
    o.dt = 1e-4;
    o.tend = 2.0;
    samples sm = {.cap = 20000 / 3 + 1, .every = 3};
    pd_osc_summary sum;
    pd_err err;
    sm.v = malloc((size_t)sm.cap * 5 * sizeof(double));
    if (!CHECK(ctx, sm.v && pd_osc_summarize(&c, &o, collect, &sm, &sum, &err) == 0,
               "the library run"))
        goto done;
    for (int f = 0; f < 2; f++) {
        proc_out r;
        const char *args[] = {"simulate", "--ap", "4",     "--Tp",       "0.3",
                              "--Pi2",    "0.1",  "--Pi3", "0.4",        "--eps",
                              "0.6",      "--dt", "1e-4",  "--tend",     "2",
                              "--every",  "3",    "-o",    f ? csv : h5, NULL};
        run(ctx, args, NULL, &r, NULL);
        CHECK(ctx, r.status == 0 && r.err[0] == '\0', "%s: exit %d: %s", f ? "csv" : "h5", r.status,
              r.err);
        pd_test_proc_free(&r);
    }
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t file = H5Fopen(h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (!CHECK(ctx, file >= 0, "cannot open %s", h5))
        goto done;
    for (int j = 0; j < 5; j++) {
        long n, bad = 0;
        double *x = read_dataset(file, cols[j], &n);
        CHECK(ctx, n == sm.n, "%s: %ld rows, the run sampled %ld", cols[j], n, sm.n);
        for (long i = 0; x && i < n && i < sm.n; i++)
            bad += memcmp(&x[i], &sm.v[5 * i + j], sizeof(double)) != 0;
        CHECK(ctx, x && bad == 0, "%s: %ld values differ from the run's samples", cols[j], bad);
        free(x);
    }
    CHECK(ctx,
          pd_test_h5_num(file, "umax") == sum.r.umax && pd_test_h5_num(file, "every") == 3 &&
              pd_test_h5_num(file, "steps") == (double)sum.r.steps,
          "attributes umax %.17g (run %.17g), every, steps", pd_test_h5_num(file, "umax"),
          sum.r.umax);
    H5Fclose(file);
    char *text = pd_test_slurp(csv), *p = text ? strstr(text, "\nt,u,v,impulse,gap\n") : NULL;
    long rows = 0, bad = 0;
    for (p = p ? p + 19 : NULL; p && *p && rows < sm.n; rows++)
        for (int j = 0; j < 5; j++) {
            double x = strtod(p, &p);
            bad += memcmp(&x, &sm.v[5 * rows + j], sizeof x) != 0;
            p += *p == ',' || *p == '\n';
        }
    CHECK(ctx, text && strstr(text, "# umax = ") && rows == sm.n && bad == 0 && p && !*p,
          "csv: %ld rows (run %ld), %ld values differ", rows, sm.n, bad);
    free(text);
done:
    free(sm.v);
    pd_test_rm_dir(dir);
}

/* An output estimated beyond the free space of its file system is refused
 * before the run: exit 2, one line with the sizes, no file. */
static void test_outputs_refuses_beyond_free_space(pd_test_ctx *ctx)
{
    char dir[64], out[128], tend[32];
    struct statvfs fs;
    if (!pd_test_have_pound(ctx) || scratch(ctx, "room", dir, sizeof dir))
        return;
    double freeb = statvfs(dir, &fs) == 0 ? (double)fs.f_bavail * (double)fs.f_frsize : 0.0;
    double steps = 1.5 * freeb / (5 * 23.0); /* CSV: some 23 bytes a value */
    if (!(steps > 1e3 && steps < 1.9e9)) {
        pd_test_skip(ctx, "the free space is out of the range a run can exceed");
        pd_test_rm_dir(dir);
        return;
    }
    snprintf(tend, sizeof tend, "%.6g", steps * 1e-9);
    in(dir, "huge.csv", out, sizeof out);
    const char *args[] = {"simulate", "--dt", "1e-9", "--tend", tend, "-o", out, NULL};
    proc_out r;
    double t0 = now();
    run(ctx, args, NULL, &r, NULL);
    CHECK(ctx, r.status == 2 && now() - t0 < 2.0, "exit %d after %.2f s", r.status, now() - t0);
    CHECK(ctx, r.err && strstr(r.err, "MB free") && strstr(r.err, "--every") && one_line(r.err),
          "one line with the sizes: %s", r.err);
    CHECK(ctx, pd_test_dir_entries(dir) == 0 && r.out[0] == '\0', "a file or output left");
    pd_test_proc_free(&r);
    pd_test_rm_dir(dir);
}

/* ---- 4. signals and stale temporary files ------------------------------- */

/* Wait up to 3 s until dir holds an entry starting with prefix: 1 or 0. */
static int wait_for(const char *dir, const char *prefix)
{
    for (int i = 0; i < 3000; i++) {
        if (entries_with(dir, prefix) > 0)
            return 1;
        sleep_ms(1);
    }
    return 0;
}

/* SIGTERM or SIGINT while simulate streams -o x.h5 and --dump-lcp d.h5:
 * the process dies of the signal and leaves no temporary file. */
static void test_outputs_signal_leaves_no_temp(pd_test_ctx *ctx)
{
    static const int sigs[] = {SIGTERM, SIGINT};
    char dir[64], out[128], dump[128];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "sig", dir, sizeof dir))
        return;
    in(dir, "x.h5", out, sizeof out);
    in(dir, "d.h5", dump, sizeof dump);
    for (int k = 0; k < 2; k++) {
        const char *args[] = {"simulate", "--Tp",  "0.3",   "--T0",       "3",    "--ap", "4",
                              "--gap",    "0.004", "--eps", "0.6",        "--dt", "1e-7", "--every",
                              "100",      "-o",    out,     "--dump-lcp", dump,   NULL};
        child c;
        proc_out r;
        if (!CHECK(ctx, child_start(ctx, args, NULL, &c) == 0, "fork"))
            break;
        int started = wait_for(dir, "x.h5.tmp") && wait_for(dir, "d.h5.tmp");
        sleep_ms(20);
        kill(c.pid, sigs[k]);
        child_wait(&c, &r, NULL);
        CHECK(ctx, started, "signal %d: the temporary files never appeared", sigs[k]);
        CHECK(ctx, r.status == 128 + sigs[k], "signal %d: status %d: %s", sigs[k], r.status, r.err);
        CHECK(ctx, pd_test_dir_entries(dir) == 0, "signal %d: %d files left", sigs[k],
              pd_test_dir_entries(dir));
        next_case(&r, dir);
    }
    pd_test_rm_dir(dir);
}

/* Writing F removes F.tmp<PID> (and F.tmp<PID>.rows) of processes that are
 * gone, and keeps those of a live process and other outputs' files. */
static void test_outputs_stale_temp_removed(pd_test_ctx *ctx)
{
    char dir[64], out[128], name[64], dead1[160], dead2[160], live[160], other[160];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "stale", dir, sizeof dir))
        return;
    pid_t dead = fork();
    if (dead == 0)
        _exit(0);
    waitpid(dead, NULL, 0);
    in(dir, "x.h5", out, sizeof out);
    snprintf(name, sizeof name, "x.h5.tmp%ld", (long)dead);
    in(dir, name, dead1, sizeof dead1);
    snprintf(name, sizeof name, "x.h5.tmp%ld.rows", (long)dead);
    in(dir, name, dead2, sizeof dead2);
    snprintf(name, sizeof name, "x.h5.tmp%ld", (long)getpid());
    in(dir, name, live, sizeof live);
    snprintf(name, sizeof name, "y.h5.tmp%ld", (long)dead);
    in(dir, name, other, sizeof other);
    write_file(dead1, "stale");
    write_file(dead2, "stale");
    write_file(live, "in use");
    write_file(other, "another output's");
    const char *args[] = {"simulate", "--Tp", "0.3", "--T0", "0.5", "-o", out, NULL};
    proc_out r;
    run(ctx, args, NULL, &r, NULL);
    CHECK(ctx, r.status == 0 && exists(out), "exit %d: %s", r.status, r.err);
    CHECK(ctx, !exists(dead1) && !exists(dead2), "the dead process's files are still there");
    CHECK(ctx, exists(live) && exists(other), "a live process's or another output's file went");
    pd_test_proc_free(&r);
    pd_test_rm_dir(dir);
}

/* The number of finished-task records in a journal. */
static int journal_records(const char *path)
{
    char *text = pd_test_slurp(path);
    int n = 0;
    for (const char *p = text; p && (p = strstr(p, "\nT ")); p++)
        n++;
    free(text);
    return n;
}

/* A sweep killed by SIGTERM keeps its journal and no temporary file, and
 * --resume finishes it into the file an uninterrupted sweep writes. */
static void test_outputs_spectrum_resume_after_sigterm(pd_test_ctx *ctx)
{
    char dir[64], out[128], fresh[128], journal[160];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "resume", dir, sizeof dir))
        return;
    in(dir, "s.h5", out, sizeof out);
    in(dir, "f.h5", fresh, sizeof fresh);
    snprintf(journal, sizeof journal, "%s.partial", out);
#define SWEEP_ARGS "spectrum", "--Pi2", "0.1:1:8", "--dt-per-Tp", "3000", "--threads", "1"
    const char *a_run[] = {SWEEP_ARGS, "-o", out, NULL};
    const char *a_resume[] = {SWEEP_ARGS, "-o", out, "--resume", "--json", NULL};
    const char *a_fresh[] = {SWEEP_ARGS, "-o", fresh, NULL};
#undef SWEEP_ARGS
    child c;
    proc_out r;
    if (!CHECK(ctx, child_start(ctx, a_run, NULL, &c) == 0, "fork"))
        goto done;
    for (int i = 0; i < 5000 && journal_records(journal) < 3; i++)
        sleep_ms(1);
    kill(c.pid, SIGTERM);
    child_wait(&c, &r, NULL);
    CHECK(ctx, r.status == 128 + SIGTERM, "status %d, expected death by SIGTERM: %s", r.status,
          r.err);
    CHECK(ctx, !exists(out) && exists(journal) && entries_with(dir, "s.h5.tmp") == 0,
          "after SIGTERM: expected the journal only");
    pd_test_proc_free(&r);
    run(ctx, a_resume, NULL, &r, NULL);
    CHECK(ctx, r.status == 0, "--resume: exit %d: %s", r.status, r.err);
    CHECK(ctx, pd_test_json_num(r.out, "resumed", 0) >= 3, "resumed %g runs",
          pd_test_json_num(r.out, "resumed", 0));
    CHECK(ctx, exists(out) && !exists(journal), "after --resume: the file, no journal");
    pd_test_proc_free(&r);
    run(ctx, a_fresh, NULL, &r, NULL);
    CHECK(ctx, r.status == 0 && pd_test_same_file(out, fresh),
          "the resumed file differs from an uninterrupted sweep's");
    pd_test_proc_free(&r);
done:
    pd_test_rm_dir(dir);
}

/* ---- 5, 8. targets that cannot be written ------------------------------- */

/* A run whose -o, --plot or --dump-lcp cannot be written stops before
 * computing: exit 2, "pound: FLAG PATH: <reason>", nothing on stdout, no
 * file.  A missing folder and a folder given as the file (works as root). */
static void test_outputs_missing_dir(pd_test_ctx *ctx)
{
    char dir[64], missing[160], folder[128], png[160], dump[160], msg[512];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "nodir", dir, sizeof dir))
        return;
    in(dir, "nowhere/x.h5", missing, sizeof missing);
    in(dir, "nowhere/x.png", png, sizeof png);
    in(dir, "nowhere/d.h5", dump, sizeof dump);
    in(dir, "d.h5", folder, sizeof folder);
    mkdir(folder, 0700);
    static const char *const why[] = {"No such file or directory", "No such file or directory",
                                      "Is a directory", "No such file or directory",
                                      "No such file or directory"};
    const char *flags[] = {"-o", "-o", "-o", "--plot", "--dump-lcp"};
    const char *paths[] = {missing, missing, folder, png, dump};
    for (int k = 0; k < 5; k++) {
        const char *sim[] = {"simulate", "--Tp", "0.3", "--T0", "3", flags[k], paths[k], NULL};
        const char *spec[] = {"spectrum", "--Pi2", "0.5:1:2", "-o", paths[k], NULL};
        proc_out r;
        double t0 = now();
        run(ctx, k == 1 ? spec : sim, NULL, &r, NULL);
        snprintf(msg, sizeof msg, "pound: %s %s: %s\n", flags[k], paths[k], why[k]);
        CHECK(ctx, r.status == 2 && now() - t0 < 1.5, "case %d: exit %d after %.2f s", k, r.status,
              now() - t0);
        CHECK(ctx, r.err && !strcmp(r.err, msg), "case %d: stderr '%s', expected '%s'", k,
              r.err ? r.err : "", msg);
        CHECK(ctx, r.out && r.out[0] == '\0', "case %d: stdout '%s'", k, r.out);
        CHECK(ctx, pd_test_dir_entries(dir) == 1 && pd_test_dir_entries(folder) == 0,
              "case %d: files left", k);
        pd_test_proc_free(&r);
    }
    rmdir(folder);
    pd_test_rm_dir(dir);
}

/* A read-only folder: exit 2 "Permission denied" before computing (skipped
 * as root, who may write anywhere). */
static void test_outputs_readonly_dir(pd_test_ctx *ctx)
{
    char dir[64], ro[128], out[160];
    if (geteuid() == 0) {
        pd_test_skip(ctx, "running as root: permissions do not apply");
        return;
    }
    if (!pd_test_have_pound(ctx) || scratch(ctx, "ro", dir, sizeof dir))
        return;
    in(dir, "ro", ro, sizeof ro);
    in(ro, "x.h5", out, sizeof out);
    mkdir(ro, 0555);
    const char *args[] = {"simulate", "--Tp", "0.3", "--T0", "3", "-o", out, NULL};
    proc_out r;
    run(ctx, args, NULL, &r, NULL);
    char msg[256];
    snprintf(msg, sizeof msg, "pound: -o %s: Permission denied\n", out);
    CHECK(ctx, r.status == 2 && r.err && !strcmp(r.err, msg), "exit %d: '%s'", r.status, r.err);
    CHECK(ctx, pd_test_dir_entries(ro) == 0, "a file in the read-only folder");
    pd_test_proc_free(&r);
    chmod(ro, 0700);
    rmdir(ro);
    pd_test_rm_dir(dir);
}

/* ---- 6. modes and symlinks -------------------------------------------------- */

/* Replacing an existing output keeps its permission bits; a symlink given
 * as -o stays a link and its target is replaced (a dangling one too). */
static void test_outputs_keeps_mode_and_link(pd_test_ctx *ctx)
{
    char dir[64], file[128], target[128], link[128], dangling[128], newt[128];
    struct stat st;
    if (!pd_test_have_pound(ctx) || scratch(ctx, "mode", dir, sizeof dir))
        return;
    in(dir, "x.csv", file, sizeof file);
    in(dir, "target.h5", target, sizeof target);
    in(dir, "link.h5", link, sizeof link);
    in(dir, "dangling.csv", dangling, sizeof dangling);
    in(dir, "new.csv", newt, sizeof newt);
    write_file(file, "old\n");
    chmod(file, 0600);
    write_file(target, "old\n");
    chmod(target, 0640);
    if (symlink("target.h5", link) || symlink("new.csv", dangling)) {
        CHECK(ctx, 0, "symlink: %s", strerror(errno));
        goto done;
    }
    const char *outs[] = {file, link, dangling};
    for (int k = 0; k < 3; k++) {
        const char *args[] = {"simulate", "--Tp", "0.3", "--T0", "0.5", "-o", outs[k], NULL};
        proc_out r;
        run(ctx, args, NULL, &r, NULL);
        CHECK(ctx, r.status == 0, "%s: exit %d: %s", outs[k], r.status, r.err);
        pd_test_proc_free(&r);
    }
    CHECK(ctx, stat(file, &st) == 0 && (st.st_mode & 07777) == 0600 && st.st_size > 100,
          "x.csv: mode %o, %ld bytes (expected 600, the new data)", (unsigned)(st.st_mode & 07777),
          (long)st.st_size);
    CHECK(ctx, lstat(link, &st) == 0 && S_ISLNK(st.st_mode), "link.h5 is no longer a symlink");
    CHECK(ctx, stat(target, &st) == 0 && (st.st_mode & 07777) == 0640 && st.st_size > 100,
          "target.h5: mode %o, %ld bytes (expected 640, the new data)",
          (unsigned)(st.st_mode & 07777), (long)st.st_size);
    CHECK(ctx,
          lstat(dangling, &st) == 0 && S_ISLNK(st.st_mode) && stat(newt, &st) == 0 &&
              st.st_size > 100,
          "dangling.csv: the link kept and new.csv written");
    CHECK(ctx, pd_test_dir_entries(dir) == 5, "%d files (expected 5)", pd_test_dir_entries(dir));
done:
    pd_test_rm_dir(dir);
}

/* ---- 7. spectrum journals of bad sweeps ------------------------------------ */

/* A sweep found bad only when it runs (--dt 1e308) exits 2 and leaves no
 * journal, so the next run fails the same way instead of refusing "an
 * interrupted sweep"; with --resume the journal it created goes too. */
static void test_outputs_spectrum_bad_input_no_journal(pd_test_ctx *ctx)
{
    char dir[64], out[128];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "bad", dir, sizeof dir))
        return;
    in(dir, "out.h5", out, sizeof out);
    const char *plain[] = {"spectrum", "--Pi2", "0.1:1:3", "--dt", "1e308", "-o", out, NULL};
    const char *resume[] = {"spectrum", "--Pi2", "0.1:1:3",  "--dt", "1e308",
                            "-o",       out,     "--resume", NULL};
    const char *const *cases[] = {plain, plain, resume};
    for (int k = 0; k < 3; k++) {
        proc_out r;
        run(ctx, cases[k], NULL, &r, NULL);
        CHECK(ctx,
              r.status == 2 && r.err && strstr(r.err, "dt") && !strstr(r.err, "interrupted") &&
                  one_line(r.err),
              "run %d: exit %d: %s", k, r.status, r.err);
        CHECK(ctx, pd_test_dir_entries(dir) == 0, "run %d: %d files left", k,
              pd_test_dir_entries(dir));
        pd_test_proc_free(&r);
    }
    pd_test_rm_dir(dir);
}

/* ---- 9. converge's table, dumps over old files, outputs on one file ------- */

/* Does a run's stderr say exactly "pound: CMD: FLAG PATH: File too large"? */
static int too_large(const char *err, const char *cmd, const char *flag, const char *path)
{
    char want[512];
    snprintf(want, sizeof want, "pound: %s: %s %s: File too large\n", cmd, flag, path);
    return err && !strcmp(err, want);
}

/* converge -o c.csv / c.h5 under a file-size limit below the file's size
 * (the CSV is some 550 bytes, the HDF5 file some 24 kB): exit 1, the one
 * line, no file nor temporary; above it, exit 0 and the whole file. */
static void test_outputs_full_disk_converge(pd_test_ctx *ctx)
{
    static const struct {
        const char *name;
        long limit;
        int fits;
    } cases[] = {{"c.csv", 256, 0}, {"c.csv", 512, 0}, {"c.csv", 65536, 1},
                 {"c.h5", 700, 0},  {"c.h5", 8192, 0}, {"c.h5", 65536, 1}};
    char dir[64], out[128];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "cdisk", dir, sizeof dir))
        return;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        proc_out r;
        struct stat st;
        child_opts o = {.fsize = cases[k].limit};
        in(dir, cases[k].name, out, sizeof out);
        const char *args[] = {"converge", "--dt", "1e-2:1e-3:3", "-o", out, NULL};
        run(ctx, args, &o, &r, NULL);
        if (cases[k].fits) {
            CHECK(ctx, r.status == 0 && r.err[0] == '\0', "%s at %ld bytes: exit %d: %s",
                  cases[k].name, cases[k].limit, r.status, r.err);
            CHECK(ctx,
                  stat(out, &st) == 0 && st.st_size > 400 && st.st_size < cases[k].limit &&
                      pd_test_dir_entries(dir) == 1,
                  "%s at %ld bytes: the whole file alone (%ld bytes)", cases[k].name,
                  cases[k].limit, (long)st.st_size);
        } else
            expect_too_large(ctx, &r, cases[k].name, cases[k].limit,
                             too_large(r.err, "converge", "-o", out), dir);
        next_case(&r, dir);
    }
    pd_test_rm_dir(dir);
}

/* simulate --chain 5 --dump-lcp d.h5 under file-size limits: exit 1 with
 * the one line; in an empty folder nothing is left, and a d.h5 that was
 * there before (the stress suite's input) is kept byte for byte, alone. */
static void test_outputs_full_disk_dump_keeps_old(pd_test_ctx *ctx)
{
    static const long limits[] = {700, 8192, 65536};
    static const char old[] = "an older dump\n";
    char dir[64], dump[128];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "ddisk", dir, sizeof dir))
        return;
    in(dir, "d.h5", dump, sizeof dump);
    for (int k = 0; k < 6; k++) {
        proc_out r;
        long limit = limits[k % 3];
        int had = k >= 3;
        child_opts o = {.fsize = limit};
        const char *args[] = {"simulate", "--chain", "5", "--tend", "1", "--dump-lcp", dump, NULL};
        if (had && !CHECK(ctx, write_file(dump, old) == 0, "the old dump"))
            break;
        run(ctx, args, &o, &r, NULL);
        char *text = had ? pd_test_slurp(dump) : NULL;
        CHECK(ctx, r.status == 1 && too_large(r.err, "simulate", "--dump-lcp", dump),
              "%ld bytes%s: exit %d: '%s'", limit, had ? " (old d.h5)" : "", r.status, r.err);
        CHECK(ctx, pd_test_dir_entries(dir) == had && (!had || (text && !strcmp(text, old))),
              "%ld bytes%s: %d files, the old dump %s", limit, had ? " (old d.h5)" : "",
              pd_test_dir_entries(dir),
              had ? (text && !strcmp(text, old) ? "kept" : "changed") : "-");
        free(text);
        next_case(&r, dir);
    }
    pd_test_rm_dir(dir);
}

/* Two outputs of one run naming one file — the same name, another
 * spelling, a symlink, a hard link, a chart --plot implies — are refused
 * before the run: exit 2, one line naming both, nothing written (simulate
 * used to write -o and --dump-lcp through one temporary file, exit 1 with
 * "No such file or directory" and leave d2.h5). */
static void test_outputs_same_file_refused(pd_test_ctx *ctx)
{
    char dir[64], base[64], d2[128], dot[160], up[192], lnk[128], hard[128], e[128], png[128],
        plink[128], wlink[128], glink[128], scene[128];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "same", dir, sizeof dir))
        return;
    const char *slash = strrchr(dir, '/');
    snprintf(base, sizeof base, "%s", slash + 1);
    in(dir, "d2.h5", d2, sizeof d2);
    in(dir, "./d2.h5", dot, sizeof dot);
    snprintf(up, sizeof up, "%s/../%s/d2.h5", dir, base);
    in(dir, "link.h5", lnk, sizeof lnk);
    in(dir, "e.h5", e, sizeof e);
    in(dir, "hard.h5", hard, sizeof hard);
    in(dir, "x.png", png, sizeof png);
    in(dir, "p.h5", plink, sizeof plink);
    in(dir, "w.h5", wlink, sizeof wlink);
    in(dir, "g.h5", glink, sizeof glink);
    in(dir, "s.json", scene, sizeof scene);
    if (!CHECK(ctx,
               symlink("d2.h5", lnk) == 0 && write_file(e, "old\n") == 0 && link(e, hard) == 0 &&
                   symlink("x.png", plink) == 0 && symlink("x-work.png", wlink) == 0 &&
                   symlink("x-gamma.png", glink) == 0 && write_file(scene, two_sdof) == 0,
               "the links: %s", strerror(errno)))
        goto done;
    const int files = 7; /* link.h5, e.h5, hard.h5, p.h5, w.h5, g.h5, s.json */
    const struct {
        const char *args[12];
        const char *f1, *f2;
    } cases[] = {
        {{"simulate", "--dump-lcp", d2, "-o", d2, NULL}, "-o", "--dump-lcp"},
        {{"simulate", "--dump-lcp", d2, "-o", dot, NULL}, "-o", "--dump-lcp"},
        {{"simulate", "--dump-lcp", d2, "-o", up, NULL}, "-o", "--dump-lcp"},
        {{"simulate", "--chain", "3", "--dump-lcp", d2, "-o", lnk, NULL}, "-o", "--dump-lcp"},
        {{"simulate", "--dump-lcp", e, "-o", hard, NULL}, "-o", "--dump-lcp"},
        {{"simulate", "--plot", png, "-o", plink, NULL}, "-o", "--plot"},
        {{"converge", "--dt", "1e-2:1e-3:2", "--plot", png, "-o", plink, NULL}, "-o", "--plot"},
        {{"converge", "--dt", "1e-2:1e-3:2", "--plot", png, "-o", wlink, NULL}, "-o", "--plot"},
        {{"spectrum", "--Pi2", "0.5:1:2", "--plot", png, "-o", plink, NULL}, "-o", "--plot"},
        {{"spectrum", "--Pi2", "0.5:1:2", "--plot", png, "-o", glink, NULL}, "-o", "--plot"},
        {{"spectrum", "--scene", scene, "--Pi2", "0.5:1:2", "--plot", png, "-o", plink, NULL},
         "-o",
         "--plot"}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        proc_out r;
        run(ctx, cases[k].args, NULL, &r, NULL);
        CHECK(ctx, r.status == 2, "case %zu (%s): exit %d: %s", k, cases[k].args[0], r.status,
              r.err);
        CHECK(ctx,
              one_line(r.err) && strstr(r.err, "name the same file") &&
                  strstr(r.err, cases[k].f1) && strstr(r.err, cases[k].f2),
              "case %zu (%s): stderr '%s'", k, cases[k].args[0], r.err);
        CHECK(ctx,
              r.out[0] == '\0' && pd_test_dir_entries(dir) == files && !exists(d2) && !exists(png),
              "case %zu (%s): %d entries (expected the %d made by the test)", k, cases[k].args[0],
              pd_test_dir_entries(dir), files);
        pd_test_proc_free(&r);
    }
    /* distinct files still run */
    proc_out r;
    const char *ok[] = {"simulate",   "--chain", "3",  "--tend", "0.5",
                        "--dump-lcp", d2,        "-o", e,        NULL};
    run(ctx, ok, NULL, &r, NULL);
    CHECK(ctx, r.status == 0 && exists(d2), "-o e.h5 --dump-lcp d2.h5: exit %d: %s", r.status,
          r.err);
    pd_test_proc_free(&r);
done:
    pd_test_rm_dir(dir);
}

/* A string attribute of obj into buf ("" when missing). */
static void h5_text_attr(hid_t obj, const char *name, char *buf, size_t cap)
{
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT), t = a >= 0 ? H5Aget_type(a) : -1;
    buf[0] = '\0';
    if (t >= 0 && H5Tget_class(t) == H5T_STRING && H5Tget_size(t) < cap)
        H5Aread(a, t, buf);
    if (t >= 0)
        H5Tclose(t);
    if (a >= 0)
        H5Aclose(a);
}

/* converge -o: the method is text in the CSV ("moreau", "penalty", as in
 * --json), a code in the HDF5 file with a "codes" attribute naming it. */
static void test_outputs_converge_method_text(pd_test_ctx *ctx)
{
    char dir[64], csv[128], h5[128], codes[128], name[32];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "meth", dir, sizeof dir))
        return;
    in(dir, "c.csv", csv, sizeof csv);
    in(dir, "c.h5", h5, sizeof h5);
    for (int f = 0; f < 2; f++) {
        proc_out r;
        const char *args[] = {"converge",       "--dt",   "1e-2:1e-3:2", "--methods",
                              "moreau,penalty", "--kcs",  "1e2",         "-o",
                              f ? h5 : csv,     "--json", NULL};
        run(ctx, args, NULL, &r, NULL);
        CHECK(ctx, r.status == 0, "%s: exit %d: %s", f ? "h5" : "csv", r.status, r.err);
        pd_test_json_str(r.out, "method", 0, name, sizeof name);
        CHECK(ctx, !strcmp(name, "moreau"), "--json: first method '%s'", name);
        pd_test_json_str(r.out, "method", 2, name, sizeof name);
        CHECK(ctx, !strcmp(name, "penalty"), "--json: third method '%s'", name);
        pd_test_proc_free(&r);
    }
    char *text = pd_test_slurp(csv), *hdr = text ? strstr(text, "\nmethod,theta,") : NULL;
    int rows[3] = {0, 0, 0}; /* moreau, penalty, other */
    for (char *p = hdr ? strchr(hdr + 1, '\n') : NULL; p && p[1]; p = strchr(p + 1, '\n'))
        rows[!strncmp(p + 1, "moreau,", 7) ? 0 : !strncmp(p + 1, "penalty,", 8) ? 1 : 2]++;
    CHECK(ctx, hdr && rows[0] == 2 && rows[1] == 1 && rows[2] == 0,
          "csv: %d moreau rows, %d penalty rows, %d others (expected 2, 1, 0)", rows[0], rows[1],
          rows[2]);
    free(text);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t file = H5Fopen(h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    hid_t ds = file >= 0 ? H5Dopen2(file, "method", H5P_DEFAULT) : -1;
    long n = -1;
    double *x = file >= 0 ? read_dataset(file, "method", &n) : NULL;
    if (ds >= 0)
        h5_text_attr(ds, "codes", codes, sizeof codes);
    CHECK(ctx, ds >= 0 && strstr(codes, "0 = moreau") && strstr(codes, "2 = penalty"),
          "h5: method's codes attribute '%s'", ds >= 0 ? codes : "(no dataset)");
    CHECK(ctx, x && n == 3 && x[0] == 0 && x[1] == 0 && x[2] == 2, "h5: method codes %ld rows", n);
    free(x);
    if (ds >= 0)
        H5Dclose(ds);
    if (file >= 0)
        H5Fclose(file);
    pd_test_rm_dir(dir);
}

/* ---- provenance (issue 12, docs/formats.md) -------------------------------- */

/* Is s a UTC ISO 8601 time, YYYY-MM-DDTHH:MM:SSZ? */
static int iso_utc(const char *s)
{
    static const char shape[] = "dddd-dd-ddTdd:dd:ddZ";
    if (strlen(s) != sizeof shape - 1)
        return 0;
    for (size_t i = 0; i < sizeof shape - 1; i++)
        if (shape[i] == 'd' ? !(s[i] >= '0' && s[i] <= '9') : s[i] != shape[i])
            return 0;
    return 1;
}

/* Every -o file records its provenance: simulate -o F.h5 (a name the shell
 * must quote) has the root attributes format, command (the arguments,
 * quoted as shlex.quote does), pound_version (pd_version()) and created
 * (UTC ISO 8601), and every dataset a units attribute; the CSV starts with
 * the same four '#' lines and has a "# units = " line, one unit per column;
 * a spectrum file has no created and a command without -o and --threads
 * (equal sweeps, equal bytes). */
static void test_outputs_provenance(pd_test_ctx *ctx)
{
    static const char *const cols[] = {"t", "u", "v", "impulse", "gap"};
    char dir[64], h5[128], csv[128], spec[128], want[512], buf[1024];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "prov", dir, sizeof dir))
        return;
    in(dir, "it's.h5", h5, sizeof h5);
    in(dir, "run.csv", csv, sizeof csv);
    in(dir, "s.h5", spec, sizeof spec);
    for (int f = 0; f < 2; f++) {
        proc_out r;
        const char *args[] = {"simulate", "--tend", "0.5",        "--every",
                              "10",       "-o",     f ? csv : h5, NULL};
        run(ctx, args, NULL, &r, NULL);
        CHECK(ctx, r.status == 0, "simulate -o %s: exit %d: %s", f ? "csv" : "h5", r.status, r.err);
        pd_test_proc_free(&r);
    }
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t file = H5Fopen(h5, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (CHECK(ctx, file >= 0, "cannot open %s", h5)) {
        h5_text_attr(file, "format", buf, sizeof buf);
        CHECK(ctx, !strcmp(buf, "pound simulate oscillator 1"), "format '%s'", buf);
        snprintf(want, sizeof want, "pound simulate --tend 0.5 --every 10 -o '%s/it'\"'\"'s.h5'",
                 dir);
        h5_text_attr(file, "command", buf, sizeof buf);
        CHECK(ctx, !strcmp(buf, want), "command '%s', expected '%s'", buf, want);
        h5_text_attr(file, "pound_version", buf, sizeof buf);
        CHECK(ctx, !strcmp(buf, pd_version()), "pound_version '%s', expected '%s'", buf,
              pd_version());
        h5_text_attr(file, "created", buf, sizeof buf);
        CHECK(ctx, iso_utc(buf), "created '%s' is not YYYY-MM-DDTHH:MM:SSZ", buf);
        for (int j = 0; j < 5; j++) {
            hid_t ds = H5Dopen2(file, cols[j], H5P_DEFAULT);
            buf[0] = '\0';
            if (ds >= 0)
                h5_text_attr(ds, "units", buf, sizeof buf);
            CHECK(ctx, ds >= 0 && buf[0], "dataset %s: no units", cols[j]);
            if (ds >= 0)
                H5Dclose(ds);
        }
        H5Fclose(file);
    }
    char *text = pd_test_slurp(csv);
    snprintf(
        want, sizeof want,
        "# format = pound simulate oscillator 1\n# command = pound simulate --tend 0.5 --every "
        "10 -o %s\n# pound_version = %s\n# created = ",
        csv, pd_version());
    CHECK(ctx,
          text && !strncmp(text, want, strlen(want)) && iso_utc(strtok(text + strlen(want), "\n")),
          "csv: the first lines are not the provenance: '%.200s'", text ? text : "(none)");
    free(text);
    text = pd_test_slurp(csv);
    CHECK(ctx, text && strstr(text, "\n# units = s,m,m/s,m/s,m\nt,u,v,impulse,gap\n"),
          "csv: no '# units = s,m,m/s,m/s,m' line before the header");
    free(text);
    proc_out r;
    const char *a_spec[] = {"spectrum", "--Pi2", "0.5:1:2", "--threads", "1", "-o", spec, NULL};
    run(ctx, a_spec, NULL, &r, NULL);
    CHECK(ctx, r.status == 0, "spectrum -o: exit %d: %s", r.status, r.err);
    pd_test_proc_free(&r);
    file = H5Fopen(spec, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (CHECK(ctx, file >= 0, "cannot open %s", spec)) {
        h5_text_attr(file, "command", buf, sizeof buf);
        CHECK(ctx, !strcmp(buf, "pound spectrum --Pi2 0.5:1:2"), "spectrum command '%s'", buf);
        h5_text_attr(file, "format", buf, sizeof buf);
        CHECK(ctx, !strcmp(buf, "pound spectrum 1"), "spectrum format '%s'", buf);
        CHECK(ctx, H5Aexists(file, "created") == 0, "a spectrum file records created");
        H5Fclose(file);
    }
    pd_test_rm_dir(dir);
}

/* FIFOs: as --scene, --record or -o, --dump-lcp, --plot each is refused
 * with exit 2 and one line (an input FIFO hung for ever; an output FIFO was
 * replaced by a file), and the FIFO is left as it was. */
static void test_outputs_fifos_refused(pd_test_ctx *ctx)
{
    char dir[64], f[5][128];
    static const char *const names[] = {"in.json", "in.txt", "out.csv", "dump.h5", "p.png"};
    if (!pd_test_have_pound(ctx) || scratch(ctx, "fifo", dir, sizeof dir))
        return;
    for (int k = 0; k < 5; k++)
        if (!CHECK(ctx, mkfifo(in(dir, names[k], f[k], sizeof f[k]), 0600) == 0, "mkfifo"))
            goto done;
    const char *scene[] = {"simulate", "--scene", f[0], NULL};
    const char *rec[] = {"simulate", "--record", f[1], NULL};
    const char *out[] = {"simulate", "-o", f[2], NULL};
    const char *dump[] = {"simulate", "--chain", "3", "--dump-lcp", f[3], NULL};
    const char *plot[] = {"simulate", "--plot", f[4], NULL};
    const char *const *cases[] = {scene, rec, out, dump, plot};
    for (int k = 0; k < 5; k++) {
        proc_out r;
        struct stat st;
        run(ctx, cases[k], NULL, &r, NULL);
        CHECK(ctx,
              r.status == 2 && one_line(r.err) && strstr(r.err, "not a regular file (a FIFO)") &&
                  stat(f[k], &st) == 0 && S_ISFIFO(st.st_mode),
              "%s: exit %d, %s", names[k], r.status, r.err);
        pd_test_proc_free(&r);
    }
done:
    pd_test_rm_dir(dir);
}

/* A scene of 5001 structures (no contacts): HDF5 keeps two open datasets per
 * group, 690 MB and 6.5 s at 10,000 (stress: 100,001 structures died of a
 * 4 GiB address limit with SIGSEGV, leaving out.h5.tmpPID).  Refused up
 * front (exit 2, naming -o and the count), nothing written; CSV runs it. */
static void test_outputs_h5_groups_bounded(pd_test_ctx *ctx)
{
    char dir[64], path[128], h5[128], csv[128];
    if (!pd_test_have_pound(ctx) || scratch(ctx, "groups", dir, sizeof dir))
        return;
    FILE *f = fopen(in(dir, "wide.json", path, sizeof path), "w");
    if (!CHECK(ctx, f != NULL, "cannot write %s", path))
        goto done;
    fprintf(f, "{\"excitation\": {\"pulse\": \"sine\", \"ap\": 3, \"Tp\": 0.5},\n"
               " \"tend\": 0.001, \"structures\": [");
    for (int k = 0; k < 5001; k++)
        fprintf(f, "%s{\"name\": \"s%d\", \"T0\": 0.5}", k ? ", " : "", k);
    fprintf(f, "]}\n");
    fclose(f);
    in(dir, "o.h5", h5, sizeof h5);
    in(dir, "o.csv", csv, sizeof csv);
    const char *a5[] = {"simulate", "--scene", path, "-o", h5, NULL};
    const char *ac[] = {"simulate", "--scene", path, "-o", csv, NULL};
    proc_out r;
    run(ctx, a5, NULL, &r, NULL);
    CHECK(ctx,
          r.status == 2 && one_line(r.err) && strstr(r.err, "-o ") &&
              strstr(r.err, "5001 structures") && pd_test_dir_entries(dir) == 1,
          "HDF5: exit %d, %s, %d entries", r.status, r.err, pd_test_dir_entries(dir));
    pd_test_proc_free(&r);
    run(ctx, ac, NULL, &r, NULL);
    CHECK(ctx, r.status == 0 && pd_test_dir_entries(dir) == 2, "CSV: exit %d, %s", r.status, r.err);
    pd_test_proc_free(&r);
done:
    pd_test_rm_dir(dir);
}

void suite_outputs(pd_test_ctx *ctx)
{
    PD_RUN(ctx, test_outputs_h5_groups_bounded);
    PD_RUN(ctx, test_outputs_full_disk_simulate);
    PD_RUN(ctx, test_outputs_fifos_refused);
    PD_RUN(ctx, test_outputs_full_disk_spectrum);
    PD_RUN(ctx, test_outputs_stdout_write_error);
    PD_RUN(ctx, test_outputs_memory_bounded);
    PD_RUN(ctx, test_outputs_content_unchanged);
    PD_RUN(ctx, test_outputs_refuses_beyond_free_space);
    PD_RUN(ctx, test_outputs_signal_leaves_no_temp);
    PD_RUN(ctx, test_outputs_stale_temp_removed);
    PD_RUN(ctx, test_outputs_spectrum_resume_after_sigterm);
    PD_RUN(ctx, test_outputs_missing_dir);
    PD_RUN(ctx, test_outputs_readonly_dir);
    PD_RUN(ctx, test_outputs_keeps_mode_and_link);
    PD_RUN(ctx, test_outputs_spectrum_bad_input_no_journal);
    PD_RUN(ctx, test_outputs_full_disk_converge);
    PD_RUN(ctx, test_outputs_full_disk_dump_keeps_old);
    PD_RUN(ctx, test_outputs_same_file_refused);
    PD_RUN(ctx, test_outputs_converge_method_text);
    PD_RUN(ctx, test_outputs_provenance);
}
