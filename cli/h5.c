/* h5.c — (cli) the HDF5 helpers the output writers share, and the "sink"
 * file driver every output file is written through (pd_h5.h). */
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pd_alloc.h"
#include "pd_h5.h"

/* ---- the sink driver --------------------------------------------------------
 * sec2's features (so the library lays the file out byte for byte as sec2
 * would, without driver info in the superblock: any HDF5 reader opens it),
 * pread/pwrite on one descriptor, and failures kept from the library: the
 * first one's errno goes to the owner's cell, later writes are dropped. */

/* What the file-access property list carries: the owner's failure cell. */
typedef struct sink_info {
    int *failure;
} sink_info;

/* An open file; pub first, so that an H5FD_t * is a sink_file *. */
typedef struct sink_file {
    H5FD_t pub;
    int fd;
    haddr_t eoa, eof;
    dev_t dev;
    ino_t ino;
    int *failure;
} sink_file;

/* Remember the first failure (errno e); later ones add nothing. */
static void sink_fail(sink_file *f, int e)
{
    if (!*f->failure)
        *f->failure = e ? e : EIO;
}

/* Open or create name with the library's access flags. */
static H5FD_t *sink_open(const char *name, unsigned flags, hid_t fapl, haddr_t maxaddr)
{
    const sink_info *info = H5Pget_driver_info(fapl);
    int how = (flags & H5F_ACC_RDWR ? O_RDWR : O_RDONLY) | (flags & H5F_ACC_TRUNC ? O_TRUNC : 0) |
              (flags & H5F_ACC_CREAT ? O_CREAT : 0) | (flags & H5F_ACC_EXCL ? O_EXCL : 0);
    sink_file *f = info ? calloc(1, sizeof *f) : NULL;
    struct stat st;
    (void)maxaddr;
    if (!f)
        return NULL;
    f->failure = info->failure;
    f->fd = open(name, how, 0666);
    if (f->fd < 0 || fstat(f->fd, &st) != 0) {
        if (flags & H5F_ACC_CREAT) /* not the library's tentative open first */
            sink_fail(f, errno);
        if (f->fd >= 0)
            close(f->fd);
        free(f);
        return NULL;
    }
    f->eof = (haddr_t)st.st_size;
    f->dev = st.st_dev;
    f->ino = st.st_ino;
    return &f->pub;
}

/* Close the descriptor (a failure of close is a write failure). */
static herr_t sink_close(H5FD_t *file)
{
    sink_file *f = (sink_file *)file;
    if (close(f->fd) != 0)
        sink_fail(f, errno);
    free(f);
    return 0;
}

/* Order files by device and inode (the library's "same file" test). */
static int sink_cmp(const H5FD_t *a, const H5FD_t *b)
{
    const sink_file *x = (const sink_file *)a, *y = (const sink_file *)b;
    if (x->dev != y->dev)
        return x->dev < y->dev ? -1 : 1;
    return (x->ino > y->ino) - (x->ino < y->ino);
}

/* sec2's features, so the same layout. */
static herr_t sink_query(const H5FD_t *file, unsigned long *flags)
{
    (void)file;
    *flags = H5FD_FEAT_AGGREGATE_METADATA | H5FD_FEAT_ACCUMULATE_METADATA | H5FD_FEAT_DATA_SIEVE |
             H5FD_FEAT_AGGREGATE_SMALLDATA | H5FD_FEAT_DEFAULT_VFD_COMPATIBLE;
    return 0;
}

/* The end of the allocated address space. */
static haddr_t sink_get_eoa(const H5FD_t *file, H5FD_mem_t type)
{
    (void)type;
    return ((const sink_file *)file)->eoa;
}

static herr_t sink_set_eoa(H5FD_t *file, H5FD_mem_t type, haddr_t addr)
{
    (void)type;
    ((sink_file *)file)->eoa = addr;
    return 0;
}

/* The end of the file as written so far. */
static haddr_t sink_get_eof(const H5FD_t *file, H5FD_mem_t type)
{
    (void)type;
    return ((const sink_file *)file)->eof;
}

/* Read size bytes at addr; beyond the end of the file, zeros. */
static herr_t sink_read(H5FD_t *file, H5FD_mem_t type, hid_t dxpl, haddr_t addr, size_t size,
                        void *buf)
{
    sink_file *f = (sink_file *)file;
    char *p = buf;
    (void)type;
    (void)dxpl;
    while (size > 0) {
        ssize_t n = pread(f->fd, p, size, (off_t)addr);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0 && !*f->failure)
            return -1;
        if (n <= 0)
            break;
        p += n;
        addr += (haddr_t)n;
        size -= (size_t)n;
    }
    memset(p, 0, size);
    return 0;
}

/* Write size bytes at addr, or drop them after a failure. */
static herr_t sink_write(H5FD_t *file, H5FD_mem_t type, hid_t dxpl, haddr_t addr, size_t size,
                         const void *buf)
{
    sink_file *f = (sink_file *)file;
    const char *p = buf;
    haddr_t end = addr + size;
    (void)type;
    (void)dxpl;
    while (size > 0 && !*f->failure) {
        ssize_t n = pwrite(f->fd, p, size, (off_t)addr);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            sink_fail(f, n < 0 ? errno : ENOSPC);
            break;
        }
        p += n;
        addr += (haddr_t)n;
        size -= (size_t)n;
    }
    f->eof = end > f->eof ? end : f->eof;
    return 0;
}

/* Set the file's length to the allocated address space (unless failed). */
static herr_t sink_truncate(H5FD_t *file, hid_t dxpl, hbool_t closing)
{
    sink_file *f = (sink_file *)file;
    (void)dxpl;
    (void)closing;
    if (f->eoa != f->eof && !*f->failure && ftruncate(f->fd, (off_t)f->eoa) != 0)
        sink_fail(f, errno);
    f->eof = f->eoa;
    return 0;
}

static const H5FD_class_t sink_class = {
#ifdef H5FD_CLASS_VERSION /* HDF5 >= 1.14 numbers its driver classes */
    .version = H5FD_CLASS_VERSION,
    .value = 601,
#endif
    .name = "pound_sink",
    .maxaddr = (haddr_t)INT64_MAX,
    .fc_degree = H5F_CLOSE_WEAK,
    .fapl_size = sizeof(sink_info),
    .open = sink_open,
    .close = sink_close,
    .cmp = sink_cmp,
    .query = sink_query,
    .get_eoa = sink_get_eoa,
    .set_eoa = sink_set_eoa,
    .get_eof = sink_get_eof,
    .read = sink_read,
    .write = sink_write,
    .truncate = sink_truncate,
    .fl_map = H5FD_FLMAP_DICHOTOMY,
};

int pd_h5_headroom(double bytes)
{
    struct rlimit lim;
    if (getrlimit(RLIMIT_AS, &lim) != 0 || lim.rlim_cur == RLIM_INFINITY)
        return 0;
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long pages = 0;
    int got = f && fscanf(f, "%lu", &pages) == 1;
    if (f)
        fclose(f);
    if (!got)
        return 0;
    double used = (double)pages * (double)sysconf(_SC_PAGESIZE);
    return (double)lim.rlim_cur - used < bytes ? ENOMEM : 0;
}

int pd_h5_errno(void)
{
    return errno == ENOMEM ? ENOMEM : EIO;
}

void pd_h5_start(void)
{
    /* no clean-up at exit: a file a failed run could not close (out of
     * memory inside the library) would be closed then through its freed
     * driver; the runs close what they open */
    H5dont_atexit();
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL); /* the library must not print */
    errno = 0;
}

hid_t pd_h5_create(const char *path, hid_t fcpl, int *failure)
{
    sink_info info = {.failure = failure};
    hid_t file = -1;
    *failure = 0;
    pd_h5_start();
    if ((*failure = pd_h5_headroom(PD_H5_HEADROOM)))
        return -1;
    hid_t drv = H5FDregister(&sink_class), fapl = H5Pcreate(H5P_FILE_ACCESS);
    /* no chunk cache: every append is whole chunks (a writer's buffer is
     * its datasets' chunk), and a cache of 1 MB per dataset is gigabytes
     * for scenes of thousands of structures */
    if (drv >= 0 && fapl >= 0 && H5Pset_driver(fapl, drv, &info) >= 0 &&
        H5Pset_cache(fapl, 0, 521, 0, 0.75) >= 0)
        file = H5Fcreate(path, H5F_ACC_TRUNC, fcpl, fapl);
    if (fapl >= 0)
        H5Pclose(fapl);
    if (drv >= 0) /* the open file holds its own reference to the driver */
        H5FDunregister(drv);
    if (file >= 0 && *failure) /* the superblock could not be written */
        pd_h5_close(&file, failure);
    if (file < 0 && !*failure)
        *failure = pd_h5_errno();
    return file;
}

int pd_h5_close(hid_t *file, const int *failure)
{
    int rc = 0;
    if (*file >= 0 && H5Fclose(*file) < 0)
        rc = EIO;
    *file = -1;
    return *failure ? *failure : rc;
}

int pd_h5_close_id(hid_t *id)
{
    herr_t st = 0;
    if (*id >= 0) {
        H5I_type_t t = H5Iget_type(*id);
        st = t == H5I_DATASET       ? H5Dclose(*id)
             : t == H5I_GROUP       ? H5Gclose(*id)
             : t == H5I_GENPROP_LST ? H5Pclose(*id)
             : t == H5I_DATASPACE   ? H5Sclose(*id)
             : t == H5I_DATATYPE    ? H5Tclose(*id)
                                    : -1;
    }
    *id = -1;
    return st < 0 ? -1 : 0;
}

/* A scalar attribute: text when text is non-NULL, else the number x.  Text
 * is a fixed-length, null-terminated UTF-8 string of at least 2 bytes (a
 * 1-byte string is a netCDF "char", which h5netcdf leaves as bytes). */
int pd_h5_attr(hid_t obj, const char *name, const char *text, double x)
{
    hid_t space = H5Screate(H5S_SCALAR), type = -1, attr = -1;
    herr_t st = -1;
    if (space < 0)
        return -1;
    if (text) {
        size_t len = strlen(text);
        char pad[2] = "";
        type = H5Tcopy(H5T_C_S1);
        if (len == 0) /* "" as 2 bytes: the library reads size bytes from text */
            text = pad;
        if (type >= 0 && H5Tset_size(type, len < 1 ? 2 : len + 1) >= 0 &&
            H5Tset_cset(type, H5T_CSET_UTF8) >= 0 &&
            (attr = H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT)) >= 0)
            st = H5Awrite(attr, type, text);
    } else if ((attr = H5Acreate2(obj, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT)) >=
               0)
        st = H5Awrite(attr, H5T_NATIVE_DOUBLE, &x);
    if (attr >= 0)
        H5Aclose(attr);
    if (type >= 0)
        H5Tclose(type);
    H5Sclose(space);
    return st < 0 ? -1 : 0;
}

/* A number attribute with its "<name>_units" companion (units NULL: none). */
int pd_h5_num(hid_t obj, const char *name, double x, const char *units)
{
    char uname[160];
    if (pd_h5_attr(obj, name, NULL, x))
        return -1;
    snprintf(uname, sizeof uname, "%s_units", name);
    return units ? pd_h5_attr(obj, uname, units, 0.0) : 0;
}

/* A 1-D double array attribute of n values with its units companion. */
int pd_h5_nums(hid_t obj, const char *name, int n, const double *x, const char *units)
{
    char uname[160];
    hsize_t dims[1] = {(hsize_t)(n > 0 ? n : 1)};
    double zero = 0.0;
    hid_t space = H5Screate_simple(1, dims, NULL), attr = -1;
    herr_t st = -1;
    if (space < 0)
        return -1;
    if ((attr = H5Acreate2(obj, name, H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT)) >= 0)
        st = H5Awrite(attr, H5T_NATIVE_DOUBLE, n > 0 ? x : &zero);
    if (attr >= 0 && H5Aclose(attr) < 0)
        st = -1;
    H5Sclose(space);
    if (st < 0)
        return -1;
    snprintf(uname, sizeof uname, "%s_units", name);
    return units ? pd_h5_attr(obj, uname, units, 0.0) : 0;
}

int pd_provenance_h5(hid_t file, const pd_provenance *p)
{
    int rc = pd_h5_attr(file, "format", p->format, 0.0) ||
             pd_h5_attr(file, "command", p->command, 0.0) ||
             pd_h5_attr(file, "pound_version", p->pound_version, 0.0);
    if (!rc && p->created[0])
        rc = pd_h5_attr(file, "created", p->created, 0.0);
    return rc ? -1 : 0;
}

/* An object-creation property list without modification times (so equal
 * runs give byte-identical files). */
hid_t pd_h5_untimed(hid_t cls)
{
    hid_t p = H5Pcreate(cls);
    if (p >= 0 && H5Pset_obj_track_times(p, 0) < 0) {
        H5Pclose(p);
        return -1;
    }
    return p;
}

/* An extendible chunked dataset of rows x cols (cols 0: 1-D) of type with
 * units; many: with the object header that takes attributes of any size. */
static hid_t extendible(hid_t loc, const char *name, hid_t type, int cols, long chunk,
                        const char *units, int many)
{
    int rank = cols > 0 ? 2 : 1;
    hsize_t dims[2] = {0, (hsize_t)cols}, maxd[2] = {H5S_UNLIMITED, (hsize_t)cols};
    hsize_t ch[2] = {(hsize_t)chunk, (hsize_t)(cols > 0 ? cols : 1)};
    hid_t space = H5Screate_simple(rank, dims, maxd), dcpl = pd_h5_untimed(H5P_DATASET_CREATE);
    hid_t ds = -1;
    /* tracking the attributes' order gives a version-2 object header, whose
     * attributes move to dense storage when one outgrows the header (64 kB) */
    if (space >= 0 && dcpl >= 0 && H5Pset_chunk(dcpl, rank, ch) >= 0 &&
        (!many || H5Pset_attr_creation_order(dcpl, H5P_CRT_ORDER_TRACKED) >= 0))
        ds = H5Dcreate2(loc, name, type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (ds >= 0 && pd_h5_attr(ds, "units", units, 0.0)) {
        H5Dclose(ds);
        ds = -1;
    }
    if (dcpl >= 0)
        H5Pclose(dcpl);
    if (space >= 0)
        H5Sclose(space);
    return ds;
}

hid_t pd_h5_extendible(hid_t loc, const char *name, hid_t type, int cols, long chunk,
                       const char *units)
{
    return extendible(loc, name, type, cols, chunk, units, 0);
}

hid_t pd_h5_extendible_coord(hid_t loc, const char *name, long chunk, const char *units)
{
    hid_t ds = extendible(loc, name, H5T_NATIVE_DOUBLE, 0, chunk, units, 1);
    if (ds >= 0 && pd_h5_coord(ds, name))
        pd_h5_close_id(&ds);
    return ds;
}

/* Append nrows x cols values (row-major) to an extendible dataset at row r0. */
int pd_h5_append(hid_t ds, hid_t type, long r0, long nrows, int cols, const void *x)
{
    int rank = cols > 0 ? 2 : 1;
    hsize_t size[2] = {(hsize_t)(r0 + nrows), (hsize_t)cols};
    hsize_t start[2] = {(hsize_t)r0, 0}, count[2] = {(hsize_t)nrows, (hsize_t)cols};
    if (H5Dset_extent(ds, size) < 0)
        return -1;
    hid_t fs = H5Dget_space(ds), ms = H5Screate_simple(rank, count, NULL);
    int rc = fs < 0 || ms < 0 ||
             H5Sselect_hyperslab(fs, H5S_SELECT_SET, start, NULL, count, NULL) < 0 ||
             H5Dwrite(ds, type, ms, fs, H5P_DEFAULT, x) < 0;
    if (ms >= 0)
        H5Sclose(ms);
    if (fs >= 0)
        H5Sclose(fs);
    return rc ? -1 : 0;
}

/* ---- dimension scales (netCDF-4's dimensions) ------------------------------ */

/* The NAME of a dimension that has no coordinate variable (netCDF-4's
 * convention, which h5netcdf and netCDF-C read). */
#define NC_DIM_ONLY "This is a netCDF dimension but not a netCDF variable."

int pd_h5_coord(hid_t ds, const char *dim)
{
    return H5DSset_scale(ds, dim) < 0 ? -1 : 0;
}

hid_t pd_h5_dimension(hid_t loc, const char *name, long len)
{
    char label[sizeof NC_DIM_ONLY + 16];
    hsize_t n[1] = {(hsize_t)(len > 0 ? len : 0)};
    hid_t space = H5Screate_simple(1, n, NULL), dcpl = pd_h5_untimed(H5P_DATASET_CREATE);
    hid_t ds = -1;
    snprintf(label, sizeof label, "%s%10ld", NC_DIM_ONLY, len);
    if (space >= 0 && dcpl >= 0) /* never written: no storage */
        ds = H5Dcreate2(loc, name, H5T_NATIVE_INT, space, H5P_DEFAULT, dcpl, H5P_DEFAULT);
    if (ds >= 0 && (pd_h5_attr(ds, "units", "1", 0.0) || H5DSset_scale(ds, label) < 0))
        pd_h5_close_id(&ds);
    pd_h5_close_id(&dcpl);
    pd_h5_close_id(&space);
    return ds;
}

int pd_h5_index(hid_t loc, const char *name, long n, int first, const char *units)
{
    hsize_t len[1] = {(hsize_t)(n > 0 ? n : 0)};
    int *x = pd_malloc(n, sizeof *x);
    hid_t space = H5Screate_simple(1, len, NULL), dcpl = pd_h5_untimed(H5P_DATASET_CREATE);
    hid_t ds = -1;
    int rc = -1;
    for (long k = 0; x && k < n; k++)
        x[k] = first + (int)k;
    if (x && space >= 0 && dcpl >= 0 &&
        (ds = H5Dcreate2(loc, name, H5T_NATIVE_INT, space, H5P_DEFAULT, dcpl, H5P_DEFAULT)) >= 0)
        rc = (n > 0 && H5Dwrite(ds, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, x) < 0) ||
                     pd_h5_attr(ds, "units", units, 0.0) || pd_h5_coord(ds, name)
                 ? -1
                 : 0;
    free(x);
    if (pd_h5_close_id(&ds))
        rc = -1;
    pd_h5_close_id(&dcpl);
    pd_h5_close_id(&space);
    return rc;
}

/* The dimension scale `name` seen from the group of the object at path: the
 * dataset of that name in that group or the nearest enclosing one (netCDF's
 * scoping; a group of that name, a structure named "t", is passed over);
 * -1: none. */
static hid_t find_scale(hid_t file, const char *path, const char *name)
{
    char at[1024];
    size_t dir = strlen(path);
    for (;;) {
        while (dir > 0 && path[dir - 1] != '/')
            dir--;
        if (dir == 0 ||
            (size_t)snprintf(at, sizeof at, "%.*s%s", (int)dir, path, name) >= sizeof at)
            return -1;
        if (H5Lexists(file, at, H5P_DEFAULT) > 0) {
            hid_t ds = H5Dopen2(file, at, H5P_DEFAULT); /* the library prints nothing */
            if (ds >= 0)
                return ds;
        }
        dir--; /* the '/' ending the group: up one */
    }
}

int pd_h5_dims(hid_t ds, const char *dims)
{
    char path[1024], name[64];
    ssize_t len = H5Iget_name(ds, path, sizeof path);
    hid_t file = len > 0 && (size_t)len < sizeof path ? H5Iget_file_id(ds) : -1;
    int rc = file < 0 ? -1 : 0;
    unsigned axis = 0;
    for (const char *p = dims; *p && !rc; axis++) {
        size_t k = strcspn(p, ",");
        hid_t scale = -1;
        if (k >= sizeof name)
            rc = -1;
        else {
            memcpy(name, p, k);
            name[k] = '\0';
            scale = find_scale(file, path, name);
            rc = scale < 0 || H5DSattach_scale(ds, scale, axis) < 0 ? -1 : 0;
        }
        pd_h5_close_id(&scale);
        p += k + (p[k] == ',');
    }
    if (file >= 0 && H5Fclose(file) < 0)
        rc = -1;
    return rc;
}
