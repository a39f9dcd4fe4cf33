/* pd_h5.h — (cli) the HDF5 helpers the output writers share, and the file
 * driver every output file is written through. */
#ifndef PD_H5_H
#define PD_H5_H

#include <hdf5.h>
#include <hdf5_hl.h>

#include "pd_output.h"

/* Create path (truncating it) for writing through the "sink" driver: POSIX
 * I/O like HDF5's sec2 driver (the same bytes), except that a failed write,
 * truncate or close never reaches the library.  The first failure's errno
 * goes to *failure (which must outlive the file) and every later write is
 * dropped, so the library always closes the file cleanly (a flush failing
 * inside H5Fclose otherwise leaves a half-closed file that crashes
 * H5_term_library at exit); the caller reports the reason and removes the
 * file.  fcpl: a file-creation property list or H5P_DEFAULT.  The file, or
 * -1 with *failure set (nothing left open). */
hid_t pd_h5_create(const char *path, hid_t fcpl, int *failure);

/* Start the library for pound's use (before any other call): no clean-up
 * at exit, nothing printed, errno cleared.  pd_h5_create calls it. */
void pd_h5_start(void);
/* The library's allocations fail inside it, and HDF5 1.10 does not survive
 * that (a corrupted heap, a crash at exit).  A writer calls this before
 * each block of writes: ENOMEM when the address-space limit (RLIMIT_AS)
 * leaves less than `bytes` free (then it writes nothing more and reports
 * out of memory), else 0. */
#define PD_H5_HEADROOM (64.0 * 1048576.0) /* the library's caches and indexes */
int pd_h5_headroom(double bytes);
/* The errno of a failed library call: ENOMEM when the library ran out of
 * memory, else EIO. */
int pd_h5_errno(void);

/* Close *file (set to -1); 0, or the errno of the first failure of the file
 * (EIO when the library itself failed). */
int pd_h5_close(hid_t *file, const int *failure);

/* Close a dataset, group or property list id when it is one (>= 0) and set
 * it to -1; 0, or -1 when the library failed. */
int pd_h5_close_id(hid_t *id);

/* A scalar attribute on obj: a string when text is non-NULL, else the
 * double x.  0 on success, -1 on an HDF5 failure. */
int pd_h5_attr(hid_t obj, const char *name, const char *text, double x);

/* A number attribute with its "<name>_units" companion (units NULL: none). */
int pd_h5_num(hid_t obj, const char *name, double x, const char *units);

/* A 1-D double array attribute with its units companion. */
int pd_h5_nums(hid_t obj, const char *name, int n, const double *x, const char *units);

/* The provenance (pd_output.h) as root attributes of file: format, command,
 * pound_version and, unless empty, created (strings).  0 or -1. */
int pd_provenance_h5(hid_t file, const pd_provenance *p);

/* An object-creation property list of class cls that records no times. */
hid_t pd_h5_untimed(hid_t cls);

/* An extendible dataset of rows x cols values of type (cols 0: 1-D),
 * chunked by `chunk` rows, with a "units" attribute; -1 on failure. */
hid_t pd_h5_extendible(hid_t loc, const char *name, hid_t type, int cols, long chunk,
                       const char *units);

/* ---- dimensions: what xarray (engine="h5netcdf") and netCDF-4 read --------
 * A dataset's axes are named by dimension scales (HDF5's H5DS), netCDF-4's
 * dimensions: a 1-D dataset that is its own dimension (t, storey, Pi2) is a
 * coordinate; an axis without one (a table's rows) gets a dimension that
 * has no values.  Every dataset written names every axis so: create it,
 * then pd_h5_dims(ds, "t,storey") (the scales must exist already). */

/* Make the 1-D dataset ds the coordinate of dimension dim (its own name). */
int pd_h5_coord(hid_t ds, const char *dim);

/* A dimension of length len without values (netCDF's "dimension but not a
 * variable": an int32 dataset that is never written) at loc/name; its id,
 * or -1. */
hid_t pd_h5_dimension(hid_t loc, const char *name, long len);

/* A coordinate loc/name of the n int32 values first, first + 1, ... (floor
 * numbers, contact numbers) with its units; 0 or -1. */
int pd_h5_index(hid_t loc, const char *name, long n, int first, const char *units);

/* Attach to each axis of ds the dimension named in the comma-separated
 * dims ("t,storey"), found by name in ds's group or the nearest group
 * above it that has one (netCDF's scoping).  0, or -1 (a dimension not
 * found, or the library failed). */
int pd_h5_dims(hid_t ds, const char *dims);

/* An extendible 1-D float64 coordinate loc/name (pd_h5_extendible, then
 * pd_h5_coord) that any number of datasets may be attached to (the list
 * of them, an attribute, may outgrow the 64 kB an object header holds: a
 * scene's t has two per structure and contact); -1 on failure. */
hid_t pd_h5_extendible_coord(hid_t loc, const char *name, long chunk, const char *units);

/* Append nrows x cols values (row-major) at row r0, extending the dataset. */
int pd_h5_append(hid_t ds, hid_t type, long r0, long nrows, int cols, const void *x);

#endif
