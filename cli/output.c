/* output.c — (cli) output files (pd_output.h): the checks made before a
 * run, the temporary files a signal removes, atomic replacement, checked
 * text output, and tables streamed to HDF5 or CSV. */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <hdf5.h>
#include <signal.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <time.h>
#include <unistd.h>

#include "pd_alloc.h"
#include "pd_h5.h"
#include "pd_output.h"

/* ---- temporary files a signal removes ------------------------------------ */

enum { TMP_SLOTS = 4, TMP_PATH = PD_PATH_MAX + 32 };

/* The one exception to "no globals": what the handler of SIGINT, SIGTERM
 * and the other terminating signals (pd_output_signals) must
 * remove.  A slot's path is written while its flag is 0, then published by
 * setting the flag; the handler only reads flags and paths and calls
 * unlink (async-signal-safe).  Several slots, because -o, --dump-lcp and a
 * CSV's row file can be open at once. */
static char tmp_paths[TMP_SLOTS][TMP_PATH];
static volatile sig_atomic_t tmp_live[TMP_SLOTS];

/* Remove the registered files, then die of sig (SA_RESETHAND: the default
 * action is back, and the re-raised signal is delivered on return). */
static void on_signal(int sig)
{
    for (int i = 0; i < TMP_SLOTS; i++)
        if (tmp_live[i])
            unlink(tmp_paths[i]);
    raise(sig);
}

void pd_output_signals(void)
{
    /* the signals that end a process by default, but for faults: interrupts,
     * a soft CPU limit (prlimit --cpu), timers, a closed pipe */
    static const int sigs[] = {SIGINT,    SIGTERM, SIGHUP,  SIGQUIT, SIGXCPU, SIGALRM,
                               SIGVTALRM, SIGPROF, SIGUSR1, SIGUSR2, SIGPIPE};
    struct sigaction sa = {.sa_handler = on_signal, .sa_flags = SA_RESETHAND}, old;
    sigemptyset(&sa.sa_mask);
    for (size_t k = 0; k < sizeof sigs / sizeof sigs[0]; k++)
        if (sigaction(sigs[k], NULL, &old) == 0 && old.sa_handler != SIG_IGN)
            sigaction(sigs[k], &sa, NULL);
    /* a write past the file-size limit (ulimit -f) fails with EFBIG, which
     * the writers report and clean up after, instead of killing pound with
     * its temporary left behind */
    struct sigaction ign = {.sa_handler = SIG_IGN};
    sigemptyset(&ign.sa_mask);
    sigaction(SIGXFSZ, &ign, NULL);
}

/* Register path for removal on a signal: its slot, or -1 when none is free. */
static int tmp_register(const char *path)
{
    size_t n = strlen(path);
    for (int i = 0; i < TMP_SLOTS && n < TMP_PATH; i++)
        if (!tmp_live[i]) {
            memcpy(tmp_paths[i], path, n + 1);
            atomic_signal_fence(memory_order_seq_cst); /* the path before the flag */
            tmp_live[i] = 1;
            return i;
        }
    return -1;
}

/* The file of slot is gone or in place: a signal leaves it alone. */
static void tmp_release(int slot)
{
    if (slot >= 0)
        tmp_live[slot] = 0;
}

/* ---- paths --------------------------------------------------------------- */

/* Does path end with suffix? */
static int ends_with(const char *path, const char *suffix)
{
    size_t n = strlen(path), k = strlen(suffix);
    return n > k && !strcmp(path + n - k, suffix);
}

static int is_hdf5(const char *path)
{
    return ends_with(path, ".h5") || ends_with(path, ".hdf5");
}

/* The extension rule: PD_OK or PD_EINVAL. */
static int check_extension(const char *path, pd_err *err)
{
    if (is_hdf5(path) || ends_with(path, ".csv"))
        return PD_OK;
    return pd_err_set(err, PD_EINVAL, "-o %s: the file name must end in .h5, .hdf5 or .csv", path);
}

/* The folder of path ("." when it has none) into dir; 0 or ENAMETOOLONG. */
static int dir_of(const char *path, char *dir, size_t cap)
{
    const char *slash = strrchr(path, '/');
    int n = !slash ? snprintf(dir, cap, ".")
                   : snprintf(dir, cap, "%.*s", slash == path ? 1 : (int)(slash - path), path);
    return n < 0 || (size_t)n >= cap ? ENAMETOOLONG : 0;
}

/* path.tmpPID into tmp: 0 or ENAMETOOLONG. */
static int temp_name(const char *path, char *tmp, size_t cap)
{
    int n = snprintf(tmp, cap, "%s.tmp%ld", path, (long)getpid());
    return n < 0 || (size_t)n >= cap ? ENAMETOOLONG : 0;
}

/* path with its symbolic links followed (a dangling one: where it points)
 * into out, so that the file replaced is the link's target: 0 or an errno. */
static int follow_links(const char *path, char *out, size_t cap)
{
    char cur[PD_PATH_MAX], link[PD_PATH_MAX], next[2 * PD_PATH_MAX];
    struct stat st;
    if (snprintf(cur, sizeof cur, "%s", path) >= (int)sizeof cur)
        return ENAMETOOLONG;
    for (int hops = 0; hops < 40; hops++) {
        if (lstat(cur, &st) != 0 || !S_ISLNK(st.st_mode))
            return snprintf(out, cap, "%s", cur) >= (int)cap ? ENAMETOOLONG : 0;
        ssize_t n = readlink(cur, link, sizeof link - 1);
        if (n < 0)
            return errno;
        link[n] = '\0';
        const char *slash = strrchr(cur, '/');
        if (link[0] == '/' || !slash)
            snprintf(next, sizeof next, "%s", link);
        else
            snprintf(next, sizeof next, "%.*s%s", (int)(slash + 1 - cur), cur, link);
        if (strlen(next) >= sizeof cur)
            return ENAMETOOLONG;
        memcpy(cur, next, strlen(next) + 1);
    }
    return ELOOP;
}

/* The file `real` (links followed) may be replaced: 0, EISDIR, or the
 * errno of creating a temporary file beside it (removed at once). */
static int probe(const char *real)
{
    char tmp[TMP_PATH];
    struct stat st;
    int e = stat(real, &st) == 0 && S_ISDIR(st.st_mode) ? EISDIR : temp_name(real, tmp, sizeof tmp);
    if (e)
        return e;
    unlink(tmp); /* ours by its PID: left by a dead process that had it */
    int fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL, 0600);
    if (fd < 0)
        return errno;
    close(fd);
    unlink(tmp);
    return 0;
}

/* Remove DIR/BASE.tmp<PID>[.rows] of real whose process is gone (ESRCH). */
static void remove_stale(const char *real)
{
    char dir[PD_PATH_MAX];
    const char *slash = strrchr(real, '/'), *base = slash ? slash + 1 : real;
    size_t nb = strlen(base);
    DIR *d = dir_of(real, dir, sizeof dir) ? NULL : opendir(dir);
    for (struct dirent *e; d && (e = readdir(d));) {
        const char *p = e->d_name, *num = p + nb + 4;
        char *end;
        if (strncmp(p, base, nb) || strncmp(p + nb, ".tmp", 4) || *num < '0' || *num > '9')
            continue;
        long pid = strtol(num, &end, 10);
        if ((*end && strcmp(end, ".rows")) || pid <= 0 || pid == (long)getpid() ||
            kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue;
        unlinkat(dirfd(d), p, 0);
    }
    if (d)
        closedir(d);
}

/* ---- checks before a run ------------------------------------------------- */

int pd_output_check_writable(const char *flag, const char *path, pd_err *err)
{
    char real[PD_PATH_MAX];
    struct stat st;
    int e = follow_links(path, real, sizeof real);
    if (!e && stat(real, &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode))
        return pd_err_set(err, PD_EINVAL,
                          "%s %s: not a regular file (%s): only a regular file "
                          "is replaced",
                          flag, path,
                          S_ISFIFO(st.st_mode)                         ? "a FIFO"
                          : S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode) ? "a device"
                          : S_ISSOCK(st.st_mode)                       ? "a socket"
                                                                       : "not a file");
    if (!e)
        e = probe(real);
    return e ? pd_err_set(err, PD_EINVAL, "%s %s: %s", flag, path, strerror(e)) : PD_OK;
}

int pd_output_check_path(const char *path, pd_err *err)
{
    int rc = check_extension(path, err);
    return rc ? rc : pd_output_check_writable("-o", path, err);
}

int pd_output_check_room(const char *flag, const char *path, double bytes, pd_err *err)
{
    char real[PD_PATH_MAX], dir[PD_PATH_MAX];
    struct statvfs fs;
    if (follow_links(path, real, sizeof real) || dir_of(real, dir, sizeof dir) ||
        statvfs(dir, &fs) != 0)
        return PD_OK; /* nothing known: the writes will tell */
    double avail = (double)fs.f_bavail * (double)fs.f_frsize;
    if (bytes <= avail)
        return PD_OK;
    return pd_err_set(err, PD_EINVAL, "%s %s: about %.0f MB to write, but only %.0f MB free there",
                      flag, path, bytes / 1e6, avail / 1e6);
}

/* Where an output writes: its folder (by device and inode, or by name when
 * it cannot be read), its name in it, and the file when it exists. */
typedef struct file_id {
    char dir[PD_PATH_MAX];
    const char *base; /* in real */
    char real[PD_PATH_MAX];
    struct stat dst, fst; /* the folder's, the file's (st_ino 0: not known) */
} file_id;

/* The file_id of path, symlinks followed. */
static void file_identity(const char *path, file_id *id)
{
    memset(id, 0, sizeof *id);
    if (follow_links(path, id->real, sizeof id->real))
        snprintf(id->real, sizeof id->real, "%s", path);
    const char *slash = strrchr(id->real, '/');
    id->base = slash ? slash + 1 : id->real;
    if (dir_of(id->real, id->dir, sizeof id->dir) || stat(id->dir, &id->dst) != 0)
        id->dst.st_ino = 0;
    if (stat(id->real, &id->fst) != 0)
        id->fst.st_ino = 0;
}

/* Do two file_ids name one file? */
static int same_file(const file_id *a, const file_id *b)
{
    if (a->fst.st_ino && a->fst.st_ino == b->fst.st_ino && a->fst.st_dev == b->fst.st_dev)
        return 1; /* one existing file, through links or hard links */
    if (strcmp(a->base, b->base))
        return 0;
    if (a->dst.st_ino && b->dst.st_ino)
        return a->dst.st_ino == b->dst.st_ino && a->dst.st_dev == b->dst.st_dev;
    return !strcmp(a->dir, b->dir);
}

int pd_output_check_distinct(int n, const char *const *flags, const char *const *paths, pd_err *err)
{
    file_id a, b;
    for (int i = 0; i < n; i++) {
        if (!paths[i])
            continue;
        file_identity(paths[i], &a);
        for (int j = i + 1; j < n; j++) {
            if (!paths[j])
                continue;
            file_identity(paths[j], &b);
            if (same_file(&a, &b))
                return pd_err_set(err, PD_EINVAL, "%s %s and %s %s name the same file", flags[i],
                                  paths[i], flags[j], paths[j]);
        }
    }
    return PD_OK;
}

/* ---- an output file replaced atomically ---------------------------------- */

int pd_outfile_error(const pd_outfile *o, int e, pd_err *err)
{
    return pd_err_set(err, PD_EIO, "%s %s: %s", o->flag, o->given, strerror(e ? e : EIO));
}

int pd_outfile_begin(pd_outfile *o, const char *flag, const char *given, pd_err *err)
{
    struct stat st;
    *o = (pd_outfile){.flag = flag, .given = given, .slot = -1};
    int e = follow_links(given, o->path, sizeof o->path);
    if (!e && stat(o->path, &st) == 0) {
        e = S_ISDIR(st.st_mode) ? EISDIR : 0;
        o->keep_mode = S_ISREG(st.st_mode);
        o->mode = st.st_mode & 07777;
    }
    if (!e)
        e = temp_name(o->path, o->tmp, sizeof o->tmp);
    if (e) {
        o->tmp[0] = '\0';
        return pd_outfile_error(o, e, err);
    }
    remove_stale(o->path);
    o->slot = tmp_register(o->tmp);
    return PD_OK;
}

/* Flush path's data to the device: 0 or the errno (a delayed write error
 * shows here). */
static int sync_path(const char *path)
{
    int fd = open(path, O_RDONLY), e = 0;
    if (fd < 0)
        return errno;
    if (fsync(fd) != 0 && errno != EINVAL && errno != EROFS)
        e = errno;
    close(fd);
    return e;
}

int pd_outfile_commit(pd_outfile *o, pd_err *err)
{
    int e = o->keep_mode && chmod(o->tmp, o->mode) != 0 ? errno : 0;
    if (!e)
        e = sync_path(o->tmp);
    if (!e && rename(o->tmp, o->path) != 0)
        e = errno;
    if (e) {
        pd_outfile_abort(o);
        return pd_outfile_error(o, e, err);
    }
    tmp_release(o->slot);
    o->slot = -1;
    o->tmp[0] = '\0';
    return PD_OK;
}

void pd_outfile_abort(pd_outfile *o)
{
    if (o->tmp[0])
        unlink(o->tmp);
    o->tmp[0] = '\0';
    tmp_release(o->slot);
    o->slot = -1;
}

/* ---- text files whose every write is checked ----------------------------- */

int pd_csv_open(pd_csv *c, const char *path)
{
    c->f = fopen(path, "w");
    c->failure = c->f ? 0 : errno ? errno : EIO;
    return c->failure;
}

int pd_csv_printf(pd_csv *c, const char *fmt, ...)
{
    va_list ap;
    if (c->failure)
        return -1;
    va_start(ap, fmt);
    int n = vfprintf(c->f, fmt, ap);
    va_end(ap);
    if (n < 0)
        c->failure = errno ? errno : EIO;
    return n < 0 ? -1 : 0;
}

int pd_csv_close(pd_csv *c)
{
    if (c->f && fflush(c->f) != 0 && !c->failure)
        c->failure = errno ? errno : EIO;
    if (c->f && ferror(c->f) && !c->failure)
        c->failure = EIO;
    if (c->f && fclose(c->f) != 0 && !c->failure)
        c->failure = errno ? errno : EIO;
    c->f = NULL;
    return c->failure;
}

/* ---- provenance ---------------------------------------------------------- */

/* The second exception to "no globals": the command line of the process,
 * set once by the command (pd_provenance_set) before any file is written,
 * read by every writer. */
static struct {
    char command[PD_COMMAND_MAX];
    const char *table_format;
    int reproducible;
} prov = {"pound", "pound table 1", 0};

/* Copy len bytes of s to buf at n (as much as fits, NUL-terminated): the
 * length the text would have, n + len. */
static size_t put(char *buf, size_t cap, size_t n, const char *s, size_t len)
{
    if (n + 1 < cap) {
        size_t k = len < cap - 1 - n ? len : cap - 1 - n;
        memcpy(buf + n, s, k);
        buf[n + k] = '\0';
    }
    return n + len;
}

/* Does Python's shlex.quote leave ch as it is? */
static int shell_safe(unsigned char ch)
{
    return (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') || (ch >= '0' && ch <= '9') ||
           (ch && strchr("_@%+=:,./-", ch));
}

/* arg at n, quoted for a POSIX shell as shlex.quote does: as it is when
 * every byte is safe, else in single quotes (a quote as '"'"'). */
static size_t put_quoted(char *buf, size_t cap, size_t n, const char *arg)
{
    int safe = arg[0] != '\0';
    for (const char *p = arg; *p && safe; p++)
        safe = shell_safe((unsigned char)*p);
    if (safe)
        return put(buf, cap, n, arg, strlen(arg));
    n = put(buf, cap, n, "'", 1);
    for (const char *p = arg; *p; p++)
        n = *p == '\'' ? put(buf, cap, n, "'\"'\"'", 5) : put(buf, cap, n, p, 1);
    return put(buf, cap, n, "'", 1);
}

void pd_provenance_set(int argc, char *const *argv, const char *table_format, int reproducible)
{
    size_t cap = sizeof prov.command, n = put(prov.command, cap, 0, "pound", 5);
    for (int i = 0; i < argc; i++)
        n = put_quoted(prov.command, cap, put(prov.command, cap, n, " ", 1), argv[i]);
    if (n >= cap) /* cut: marked */
        memcpy(prov.command + cap - 4, "...", 4);
    prov.table_format = table_format ? table_format : "pound table 1";
    prov.reproducible = reproducible;
}

void pd_provenance_now(pd_provenance *p, const char *format)
{
    time_t now = time(NULL);
    struct tm tm;
    p->format = format ? format : prov.table_format;
    p->command = prov.command;
    p->pound_version = pd_version();
    p->created[0] = '\0';
    if (!prov.reproducible && now != (time_t)-1 && gmtime_r(&now, &tm))
        strftime(p->created, sizeof p->created, "%Y-%m-%dT%H:%M:%SZ", &tm);
}

int pd_provenance_tables_are(const char *format)
{
    return !strcmp(prov.table_format, format);
}

int pd_csv_comment(pd_csv *c, const char *name, const char *text)
{
    pd_csv_printf(c, "# %s = ", name);
    for (const char *p = text ? text : ""; *p;) {
        size_t k = 0;
        while (p[k] && !((unsigned char)p[k] < 0x20 || p[k] == 0x7f))
            k++;
        pd_csv_printf(c, "%.*s%s", (int)k, p, p[k] ? "?" : "");
        p += k + (p[k] != '\0');
    }
    return pd_csv_printf(c, "\n");
}

int pd_provenance_csv(pd_csv *c, const pd_provenance *p)
{
    pd_csv_comment(c, "format", p->format);
    pd_csv_comment(c, "command", p->command);
    pd_csv_comment(c, "pound_version", p->pound_version);
    if (p->created[0])
        pd_csv_comment(c, "created", p->created);
    return c->failure ? -1 : 0;
}

/* ---- tables -------------------------------------------------------------- */

#define TABLE_BLOCK_ROWS 4096L /* rows buffered, and the largest HDF5 chunk */

struct pd_table_writer {
    pd_outfile out;
    int hdf5, ncols, failure; /* failure: errno of the first failed write */
    const pd_column *cols;
    const char *dim; /* the rows' dimension */
    long rows, nbuf, chunk;
    double *buf, *col; /* HDF5: TABLE_BLOCK_ROWS rows, and one column of them */
    hid_t file, *ds;
    pd_csv spill;       /* CSV: the rows so far, in an unnamed file beside the output */
    pd_provenance prov; /* taken when the file is begun */
};

/* A column's units: "1" when none are given. */
static const char *column_units(const pd_column *c)
{
    return c->units && c->units[0] ? c->units : "1";
}

/* The label of a coded column's value, or NULL (not coded, or no label). */
static const char *column_label(const pd_column *c, double v)
{
    if (!c->labels || !(v >= 0.0 && v < c->nlabels) || v != (double)(int)v)
        return NULL;
    return c->labels[(int)v];
}

/* A coded column's dataset: the "codes" attribute, "0 = a, 1 = b, ...". */
static int h5_codes_attr(hid_t ds, const pd_column *c)
{
    char codes[512] = "";
    size_t len = 0;
    for (int k = 0; k < c->nlabels && len < sizeof codes; k++)
        if (c->labels[k])
            len += (size_t)snprintf(codes + len, sizeof codes - len, "%s%d = %s", len ? ", " : "",
                                    k, c->labels[k]);
    return pd_h5_attr(ds, "codes", codes, 0.0);
}

/* HDF5: the file and one extendible dataset per column; 0 or an errno. */
static int h5_table_open(pd_table_writer *w)
{
    if ((w->file = pd_h5_create(w->out.tmp, H5P_DEFAULT, &w->failure)) < 0)
        return w->failure;
    if (pd_provenance_h5(w->file, &w->prov))
        return w->failure ? w->failure : EIO;
    for (int j = 0; j < w->ncols; j++) {
        const pd_column *c = &w->cols[j];
        w->ds[j] =
            pd_h5_extendible(w->file, c->name, H5T_NATIVE_DOUBLE, 0, w->chunk, column_units(c));
        if (w->ds[j] < 0 || (c->labels && h5_codes_attr(w->ds[j], c)))
            return w->failure ? w->failure : pd_h5_errno();
    }
    return w->failure;
}

/* CSV: the rows go to an unnamed file until the attributes are known (they
 * come first in the file); 0 or an errno. */
static int csv_spill_open(pd_table_writer *w)
{
    char name[TMP_PATH + 8];
    if (snprintf(name, sizeof name, "%s.rows", w->out.tmp) >= (int)sizeof name)
        return ENAMETOOLONG;
    unlink(name); /* ours by its PID */
    int fd = open(name, O_RDWR | O_CREAT | O_EXCL, 0600), slot = fd >= 0 ? tmp_register(name) : -1;
    if (fd < 0)
        return errno;
    unlink(name);
    tmp_release(slot);
    if (!(w->spill.f = fdopen(fd, "w+"))) {
        int e = errno;
        close(fd);
        return e;
    }
    return 0;
}

void pd_table_free(pd_table_writer *w)
{
    if (!w)
        return;
    for (int j = 0; w->ds && j < w->ncols; j++)
        pd_h5_close_id(&w->ds[j]);
    pd_h5_close(&w->file, &w->failure);
    if (w->spill.f)
        fclose(w->spill.f);
    pd_outfile_abort(&w->out);
    free(w->buf);
    free(w->col);
    free(w->ds);
    free(w);
}

int pd_table_open(pd_table_writer **out, const char *path, int ncols, const pd_column *cols,
                  const char *dim, long expected_rows, pd_err *err)
{
    pd_table_writer *w = calloc(1, sizeof *w);
    int rc, e;
    *out = NULL;
    if (!w)
        return pd_err_set(err, PD_ENOMEM, "-o %s: out of memory", path);
    *w = (pd_table_writer){.hdf5 = is_hdf5(path),
                           .ncols = ncols,
                           .cols = cols,
                           .dim = dim ? dim : "row",
                           .file = -1,
                           .out = {.slot = -1}};
    w->chunk = expected_rows < 1                  ? 1
               : expected_rows < TABLE_BLOCK_ROWS ? expected_rows
                                                  : TABLE_BLOCK_ROWS;
    pd_provenance_now(&w->prov, NULL);
    w->buf = malloc((size_t)TABLE_BLOCK_ROWS * (size_t)ncols * sizeof(double));
    w->col = malloc((size_t)TABLE_BLOCK_ROWS * sizeof(double));
    w->ds = malloc((size_t)ncols * sizeof(hid_t));
    for (int j = 0; w->ds && j < ncols; j++)
        w->ds[j] = -1;
    if (!w->buf || !w->col || !w->ds)
        rc = pd_err_set(err, PD_ENOMEM, "-o %s: out of memory for the row buffer", path);
    else if (!(rc = check_extension(path, err)) &&
             !(rc = pd_outfile_begin(&w->out, "-o", path, err)) &&
             (e = w->hdf5 ? h5_table_open(w) : csv_spill_open(w)))
        rc = pd_outfile_error(&w->out, e, err);
    if (rc) {
        pd_table_free(w);
        return rc;
    }
    *out = w;
    return PD_OK;
}

/* HDF5: the buffered rows, column by column; 0 or -1 (failed). */
static int flush_rows(pd_table_writer *w)
{
    int rc = 0;
    if (!w->failure && w->nbuf > 0 &&
        (w->failure = pd_h5_headroom(PD_H5_HEADROOM + 8.0 * (double)w->nbuf * w->ncols)))
        return -1;
    for (int j = 0; j < w->ncols && w->nbuf > 0 && !rc && !w->failure; j++) {
        for (long r = 0; r < w->nbuf; r++)
            w->col[r] = w->buf[(size_t)r * w->ncols + j];
        rc = pd_h5_append(w->ds[j], H5T_NATIVE_DOUBLE, w->rows - w->nbuf, w->nbuf, 0, w->col);
    }
    w->nbuf = 0;
    if (rc && !w->failure)
        w->failure = pd_h5_errno();
    return w->failure ? -1 : 0;
}

int pd_table_row(pd_table_writer *w, const double *row)
{
    if (w->failure)
        return -1;
    w->rows++;
    if (!w->hdf5) {
        for (int j = 0; j < w->ncols; j++) {
            const char *label = column_label(&w->cols[j], row[j]);
            char end = j + 1 < w->ncols ? ',' : '\n';
            if (label)
                pd_csv_printf(&w->spill, "%s%c", label, end);
            else
                pd_csv_printf(&w->spill, "%.17g%c", row[j], end);
        }
        w->failure = w->spill.failure;
        return w->failure ? -1 : 0;
    }
    memcpy(w->buf + (size_t)w->nbuf * w->ncols, row, (size_t)w->ncols * sizeof(double));
    return ++w->nbuf == TABLE_BLOCK_ROWS ? flush_rows(w) : 0;
}

/* An attribute plus its "<name>_units" companion. */
static int h5_attr_with_units(hid_t obj, const pd_attr *a)
{
    char uname[128];
    if (pd_h5_attr(obj, a->name, a->is_text ? a->text : NULL, a->num))
        return -1;
    if (a->units && a->units[0]) {
        snprintf(uname, sizeof uname, "%s_units", a->name);
        return pd_h5_attr(obj, uname, a->units, 0.0);
    }
    return 0;
}

/* HDF5: the rows' dimension, the column of its name or one without
 * values, attached to every other column; 0 or -1. */
static int h5_table_dims(pd_table_writer *w)
{
    int coord = -1, rc = 0;
    for (int j = 0; j < w->ncols; j++)
        if (!strcmp(w->cols[j].name, w->dim))
            coord = j;
    hid_t dim = coord < 0 ? pd_h5_dimension(w->file, w->dim, w->rows) : -1;
    if (coord >= 0 ? pd_h5_coord(w->ds[coord], w->dim) : dim < 0)
        return -1;
    for (int j = 0; j < w->ncols && !rc; j++)
        rc = j == coord ? 0 : pd_h5_dims(w->ds[j], w->dim);
    return pd_h5_close_id(&dim) || rc ? -1 : 0;
}

/* HDF5: the last rows, the attributes, the dimension, every id closed: 0
 * or an errno. */
static int h5_table_finish(pd_table_writer *w, int nattrs, const pd_attr *attrs)
{
    int rc = flush_rows(w);
    for (int i = 0; i < nattrs && !rc; i++)
        rc = h5_attr_with_units(w->file, &attrs[i]);
    rc = rc ? rc : h5_table_dims(w);
    for (int j = 0; j < w->ncols; j++)
        rc |= pd_h5_close_id(&w->ds[j]);
    int e = pd_h5_close(&w->file, &w->failure);
    return e ? e : rc ? pd_h5_errno() : 0;
}

/* Copy the rest of from into c. */
static void csv_copy(pd_csv *c, FILE *from)
{
    char buf[1 << 16];
    size_t n;
    while (!c->failure && (n = fread(buf, 1, sizeof buf, from)) > 0)
        if (fwrite(buf, 1, n, c->f) != n)
            c->failure = errno ? errno : EIO;
    if (!c->failure && ferror(from))
        c->failure = EIO;
}

/* CSV: the provenance, "# name = value [units]" lines, "# units = ..." (one
 * per column), the header row, the rows: 0 or an errno. */
static int csv_table_finish(pd_table_writer *w, int nattrs, const pd_attr *attrs)
{
    pd_csv c = {0};
    int e = w->spill.failure;
    if (!e && (fflush(w->spill.f) != 0 || fseek(w->spill.f, 0L, SEEK_SET) != 0))
        e = errno ? errno : EIO;
    if (e || (e = pd_csv_open(&c, w->out.tmp)))
        return e;
    pd_provenance_csv(&c, &w->prov);
    for (int i = 0; i < nattrs; i++) {
        const pd_attr *a = &attrs[i];
        if (a->is_text) {
            pd_csv_comment(&c, a->name, a->text);
            continue;
        }
        pd_csv_printf(&c, "# %s = %.17g", a->name, a->num);
        if (a->units && a->units[0])
            pd_csv_printf(&c, " [%s]", a->units);
        pd_csv_printf(&c, "\n");
    }
    pd_csv_printf(&c, "# units = ");
    for (int j = 0; j < w->ncols; j++)
        pd_csv_printf(&c, "%s%s", j ? "," : "", column_units(&w->cols[j]));
    pd_csv_printf(&c, "\n");
    for (int j = 0; j < w->ncols; j++)
        pd_csv_printf(&c, "%s%s", j ? "," : "", w->cols[j].name);
    pd_csv_printf(&c, "\n");
    if (!c.failure && fflush(c.f) != 0)
        c.failure = errno ? errno : EIO;
    csv_copy(&c, w->spill.f);
    return pd_csv_close(&c);
}

int pd_table_finish(pd_table_writer *w, int nattrs, const pd_attr *attrs, pd_err *err)
{
    int e = w->hdf5 ? h5_table_finish(w, nattrs, attrs) : csv_table_finish(w, nattrs, attrs);
    if (e) {
        pd_outfile_abort(&w->out);
        return pd_outfile_error(&w->out, e, err);
    }
    return pd_outfile_commit(&w->out, err);
}

int pd_output_write(const char *path, const pd_table *t, pd_err *err)
{
    pd_table_writer *w;
    double *row = pd_malloc(t->ncols, sizeof *row);
    int rc = row ? pd_table_open(&w, path, t->ncols, t->cols, t->dim, t->rows, err)
                 : pd_err_set(err, PD_ENOMEM, "-o %s: out of memory", path);
    if (rc) {
        free(row);
        return rc;
    }
    for (long r = 0; r < t->rows && !rc; r++) {
        for (int j = 0; j < t->ncols; j++)
            row[j] = t->cols[j].values[r];
        rc = pd_table_row(w, row);
    }
    rc = pd_table_finish(w, t->nattrs, t->attrs, err); /* reports a failed row too */
    pd_table_free(w);
    free(row);
    return rc;
}
