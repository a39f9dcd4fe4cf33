/* pd_h5.h — (cli) the HDF5 helper the output writers share. */
#ifndef PD_H5_H
#define PD_H5_H

#include <hdf5.h>

/* A scalar attribute on obj: a string when text is non-NULL, else the
 * double x.  0 on success, -1 on an HDF5 failure. */
int pd_h5_attr(hid_t obj, const char *name, const char *text, double x);

/* A number attribute with its "<name>_units" companion (units NULL: none). */
int pd_h5_num(hid_t obj, const char *name, double x, const char *units);

/* A 1-D double array attribute with its units companion. */
int pd_h5_nums(hid_t obj, const char *name, int n, const double *x, const char *units);

/* An object-creation property list of class cls that records no times. */
hid_t pd_h5_untimed(hid_t cls);

/* An extendible dataset of rows x cols values of type (cols 0: 1-D),
 * chunked by `chunk` rows, with a "units" attribute; -1 on failure. */
hid_t pd_h5_extendible(hid_t loc, const char *name, hid_t type, int cols, long chunk,
                       const char *units);

/* Append nrows x cols values (row-major) at row r0, extending the dataset. */
int pd_h5_append(hid_t ds, hid_t type, long r0, long nrows, int cols, const void *x);

#endif
