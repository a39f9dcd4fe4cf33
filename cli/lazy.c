/* lazy.c — the shared libraries only some runs need, loaded when first
 * called: HDF5 and its high-level library (the -o/--dump-lcp writers and
 * readers, the dimension scales) and CHOLMOD (with the BLAS it pulls in,
 * for large sparse scenes).  Linked, they cost every
 * `pound` process some 25 ms of dynamic loading and initialisation
 * (HDF5 brings its network drivers' libraries: curl, TLS, Kerberos, LDAP;
 * CHOLMOD an OpenBLAS that starts its threads) -- a hundred times the work
 * of a `simulate` or an `lcp` call (docs/api.md, start-up).
 *
 * The binary defines the functions it calls (the prototypes of the
 * libraries' headers: any mismatch is a compile error) as trampolines: the
 * first call dlopen()s the library by the soname it was built against and
 * resolves each symbol once.  HDF5's type and property-list ids, globals
 * read by its macros right after H5open(), are copied from the library's
 * by this H5open.  When a library cannot be loaded the functions return
 * the libraries' own failure values (negative ids and statuses, NULL, 0),
 * which the callers already report, after one line saying why.
 *
 * Built when the Makefile finds the sonames (PD_LAZY_HDF5, PD_LAZY_HDF5_HL,
 * PD_LAZY_CHOLMOD); otherwise the libraries are linked as usual and this
 * file is empty. */
#include <errno.h>
#include <stdio.h>
#include <string.h>

#if defined(PD_LAZY_HDF5) || defined(PD_LAZY_CHOLMOD)
#include <dlfcn.h>

/* A library loaded once; ok < 0 after a failure (reported once). */
typedef struct lazy_lib {
    const char *soname, *what;
    void *handle;
    int ok;
    int oom; /* the loader ran out of memory (its segments could not be mapped) */
} lazy_lib;

/* Symbol `name` of the library, NULL (and one line) when it cannot be had. */
static void *lazy_sym(lazy_lib *lib, const char *name)
{
    if (lib->ok == 0) {
        lib->handle = dlopen(lib->soname, RTLD_NOW | RTLD_LOCAL);
        lib->ok = lib->handle ? 1 : -1;
        if (!lib->handle) {
            const char *why = dlerror();
            lib->oom = why && (strstr(why, "map segment") || strstr(why, "memory"));
            if (!lib->oom) /* out of memory: the callers report it as such */
                fprintf(stderr, "pound: %s needs %s: %s\n", lib->what, lib->soname, why);
        }
    }
    if (lib->ok < 0) {
        if (lib->oom) /* the callers report the failure by errno */
            errno = ENOMEM;
        return NULL;
    }
    void *p = dlsym(lib->handle, name);
    if (!p)
        fprintf(stderr, "pound: %s: %s has no %s\n", lib->what, lib->soname, name);
    return p;
}

/* A trampoline: ret name params, calling the library's with args, or
 * returning fail.  The symbol is resolved on the first call. */
#define LAZY_FN(lib, ret, name, params, args, fail)                                                \
    ret name params                                                                                \
    {                                                                                              \
        static __typeof__(name) *fn;                                                               \
        if (!fn) {                                                                                 \
            void *p = lazy_sym(&lib, #name);                                                       \
            memcpy(&fn, &p, sizeof fn); /* object to function pointer, as POSIX allows */          \
        }                                                                                          \
        if (!fn && lib.oom) /* the callers report the failure by errno */                          \
            errno = ENOMEM;                                                                        \
        return fn ? fn args : (fail);                                                              \
    }
#endif

/* ---- HDF5 ------------------------------------------------------------------ */
#ifdef PD_LAZY_HDF5
#include <hdf5.h>

static lazy_lib hdf5 = {.soname = PD_LAZY_HDF5, .what = "HDF5 output"};
#define H5_FN(ret, name, params, args, fail) LAZY_FN(hdf5, ret, name, params, args, fail)

/* The ids HDF5's macros read after H5open() (H5T_NATIVE_DOUBLE is
 * (H5open(), H5T_NATIVE_DOUBLE_g)): ours, copied from the library's. */
hid_t H5T_NATIVE_DOUBLE_g = -1, H5T_NATIVE_INT_g = -1, H5T_C_S1_g = -1;
hid_t H5P_CLS_DATASET_CREATE_ID_g = -1, H5P_CLS_GROUP_CREATE_ID_g = -1;
hid_t H5P_CLS_FILE_CREATE_ID_g = -1, H5P_CLS_FILE_ACCESS_ID_g = -1;

static const struct {
    const char *name;
    hid_t *ours;
} h5_ids[] = {{"H5T_NATIVE_DOUBLE_g", &H5T_NATIVE_DOUBLE_g},
              {"H5T_NATIVE_INT_g", &H5T_NATIVE_INT_g},
              {"H5T_C_S1_g", &H5T_C_S1_g},
              {"H5P_CLS_DATASET_CREATE_ID_g", &H5P_CLS_DATASET_CREATE_ID_g},
              {"H5P_CLS_GROUP_CREATE_ID_g", &H5P_CLS_GROUP_CREATE_ID_g},
              {"H5P_CLS_FILE_CREATE_ID_g", &H5P_CLS_FILE_CREATE_ID_g},
              {"H5P_CLS_FILE_ACCESS_ID_g", &H5P_CLS_FILE_ACCESS_ID_g}};

/* The library's H5open, then its ids into ours. */
herr_t H5open(void)
{
    static __typeof__(H5open) *fn;
    if (!fn) {
        void *p = lazy_sym(&hdf5, "H5open");
        memcpy(&fn, &p, sizeof fn);
    }
    herr_t rc = fn ? fn() : -1;
    for (size_t k = 0; rc >= 0 && k < sizeof h5_ids / sizeof h5_ids[0]; k++) {
        const hid_t *theirs = lazy_sym(&hdf5, h5_ids[k].name);
        *h5_ids[k].ours = theirs ? *theirs : -1;
        rc = theirs ? rc : -1;
    }
    return rc;
}

H5_FN(herr_t, H5check_version, (unsigned majnum, unsigned minnum, unsigned relnum),
      (majnum, minnum, relnum), -1)
H5_FN(herr_t, H5dont_atexit, (void), (), -1)
H5_FN(herr_t, H5Eset_auto2, (hid_t estack_id, H5E_auto2_t func, void *client_data),
      (estack_id, func, client_data), -1)
H5_FN(H5I_type_t, H5Iget_type, (hid_t id), (id), H5I_BADID)
H5_FN(hid_t, H5Fcreate, (const char *filename, unsigned flags, hid_t fcpl_id, hid_t fapl_id),
      (filename, flags, fcpl_id, fapl_id), -1)
H5_FN(hid_t, H5Fopen, (const char *filename, unsigned flags, hid_t fapl_id),
      (filename, flags, fapl_id), -1)
H5_FN(herr_t, H5Fclose, (hid_t file_id), (file_id), -1)
H5_FN(hid_t, H5Gcreate2,
      (hid_t loc_id, const char *name, hid_t lcpl_id, hid_t gcpl_id, hid_t gapl_id),
      (loc_id, name, lcpl_id, gcpl_id, gapl_id), -1)
H5_FN(hid_t, H5Gopen2, (hid_t loc_id, const char *name, hid_t gapl_id), (loc_id, name, gapl_id), -1)
H5_FN(herr_t, H5Gclose, (hid_t group_id), (group_id), -1)
H5_FN(hid_t, H5Screate, (H5S_class_t type), (type), -1)
H5_FN(hid_t, H5Screate_simple, (int rank, const hsize_t dims[], const hsize_t maxdims[]),
      (rank, dims, maxdims), -1)
H5_FN(herr_t, H5Sclose, (hid_t space_id), (space_id), -1)
H5_FN(herr_t, H5Sselect_hyperslab,
      (hid_t space_id, H5S_seloper_t op, const hsize_t start[], const hsize_t stride[],
       const hsize_t count[], const hsize_t block[]),
      (space_id, op, start, stride, count, block), -1)
H5_FN(int, H5Sget_simple_extent_ndims, (hid_t space_id), (space_id), -1)
H5_FN(int, H5Sget_simple_extent_dims, (hid_t space_id, hsize_t dims[], hsize_t maxdims[]),
      (space_id, dims, maxdims), -1)
H5_FN(hid_t, H5Tcopy, (hid_t type_id), (type_id), -1)
H5_FN(herr_t, H5Tset_size, (hid_t type_id, size_t size), (type_id, size), -1)
H5_FN(herr_t, H5Tclose, (hid_t type_id), (type_id), -1)
H5_FN(hid_t, H5Pcreate, (hid_t cls_id), (cls_id), -1)
H5_FN(herr_t, H5Pclose, (hid_t plist_id), (plist_id), -1)
H5_FN(herr_t, H5Pset_chunk, (hid_t plist_id, int ndims, const hsize_t dim[]),
      (plist_id, ndims, dim), -1)
H5_FN(herr_t, H5Pset_obj_track_times, (hid_t plist_id, hbool_t track_times),
      (plist_id, track_times), -1)
H5_FN(herr_t, H5Pset_cache,
      (hid_t plist_id, int mdc_nelmts, size_t rdcc_nslots, size_t rdcc_nbytes, double rdcc_w0),
      (plist_id, mdc_nelmts, rdcc_nslots, rdcc_nbytes, rdcc_w0), -1)
H5_FN(herr_t, H5Pset_driver, (hid_t plist_id, hid_t driver_id, const void *driver_info),
      (plist_id, driver_id, driver_info), -1)
H5_FN(const void *, H5Pget_driver_info, (hid_t plist_id), (plist_id), NULL)
H5_FN(hid_t, H5FDregister, (const H5FD_class_t *cls), (cls), -1)
H5_FN(herr_t, H5FDunregister, (hid_t driver_id), (driver_id), -1)
H5_FN(hid_t, H5Dcreate2,
      (hid_t loc_id, const char *name, hid_t type_id, hid_t space_id, hid_t lcpl_id, hid_t dcpl_id,
       hid_t dapl_id),
      (loc_id, name, type_id, space_id, lcpl_id, dcpl_id, dapl_id), -1)
H5_FN(hid_t, H5Dopen2, (hid_t loc_id, const char *name, hid_t dapl_id), (loc_id, name, dapl_id), -1)
H5_FN(hid_t, H5Dget_space, (hid_t dset_id), (dset_id), -1)
H5_FN(herr_t, H5Dset_extent, (hid_t dset_id, const hsize_t size[]), (dset_id, size), -1)
H5_FN(herr_t, H5Dwrite,
      (hid_t dset_id, hid_t mem_type_id, hid_t mem_space_id, hid_t file_space_id, hid_t dxpl_id,
       const void *buf),
      (dset_id, mem_type_id, mem_space_id, file_space_id, dxpl_id, buf), -1)
H5_FN(herr_t, H5Dread,
      (hid_t dset_id, hid_t mem_type_id, hid_t mem_space_id, hid_t file_space_id, hid_t dxpl_id,
       void *buf),
      (dset_id, mem_type_id, mem_space_id, file_space_id, dxpl_id, buf), -1)
H5_FN(herr_t, H5Dclose, (hid_t dset_id), (dset_id), -1)
H5_FN(hid_t, H5Acreate2,
      (hid_t loc_id, const char *attr_name, hid_t type_id, hid_t space_id, hid_t acpl_id,
       hid_t aapl_id),
      (loc_id, attr_name, type_id, space_id, acpl_id, aapl_id), -1)
H5_FN(herr_t, H5Awrite, (hid_t attr_id, hid_t type_id, const void *buf), (attr_id, type_id, buf),
      -1)
H5_FN(herr_t, H5Aclose, (hid_t attr_id), (attr_id), -1)
H5_FN(herr_t, H5Tset_cset, (hid_t type_id, H5T_cset_t cset), (type_id, cset), -1)
H5_FN(htri_t, H5Lexists, (hid_t loc_id, const char *name, hid_t lapl_id), (loc_id, name, lapl_id),
      -1)
H5_FN(herr_t, H5Lcreate_hard,
      (hid_t cur_loc, const char *cur_name, hid_t dst_loc, const char *dst_name, hid_t lcpl_id,
       hid_t lapl_id),
      (cur_loc, cur_name, dst_loc, dst_name, lcpl_id, lapl_id), -1)
H5_FN(ssize_t, H5Iget_name, (hid_t id, char *name, size_t size), (id, name, size), -1)
H5_FN(hid_t, H5Iget_file_id, (hid_t id), (id), -1)
H5_FN(herr_t, H5Pset_attr_creation_order, (hid_t plist_id, unsigned crt_order_flags),
      (plist_id, crt_order_flags), -1)
#endif

/* ---- HDF5's high-level library (dimension scales) ------------------------- */
#ifdef PD_LAZY_HDF5_HL
#include <hdf5_hl.h>

/* Loaded after HDF5 (every caller has a file open): the library it needs,
 * by the same soname, is the one already loaded. */
static lazy_lib hdf5_hl = {.soname = PD_LAZY_HDF5_HL, .what = "HDF5 output (dimension scales)"};
#define H5HL_FN(ret, name, params, args, fail) LAZY_FN(hdf5_hl, ret, name, params, args, fail)

H5HL_FN(herr_t, H5DSset_scale, (hid_t dsid, const char *dimname), (dsid, dimname), -1)
H5HL_FN(herr_t, H5DSattach_scale, (hid_t did, hid_t dsid, unsigned int idx), (did, dsid, idx), -1)
#endif

/* ---- CHOLMOD --------------------------------------------------------------- */
#ifdef PD_LAZY_CHOLMOD
#include <cholmod.h>

static lazy_lib cholmod = {.soname = PD_LAZY_CHOLMOD, .what = "the sparse factor (CHOLMOD)"};
#define CH_FN(ret, name, params, args, fail) LAZY_FN(cholmod, ret, name, params, args, fail)

CH_FN(int, cholmod_start, (cholmod_common * Common), (Common), 0)
CH_FN(int, cholmod_finish, (cholmod_common * Common), (Common), 0)
CH_FN(cholmod_factor *, cholmod_analyze, (cholmod_sparse * A, cholmod_common *Common), (A, Common),
      NULL)
CH_FN(int, cholmod_factorize, (cholmod_sparse * A, cholmod_factor *L, cholmod_common *Common),
      (A, L, Common), 0)
CH_FN(int, cholmod_free_factor, (cholmod_factor * *L, cholmod_common *Common), (L, Common), 0)
#endif

#if !defined(PD_LAZY_HDF5) && !defined(PD_LAZY_CHOLMOD)
typedef int pd_lazy_unused; /* both libraries linked as usual */
#endif
