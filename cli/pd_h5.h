/* pd_h5.h — (cli) the HDF5 helper the output writers share. */
#ifndef PD_H5_H
#define PD_H5_H

#include <hdf5.h>

/* A scalar attribute on obj: a string when text is non-NULL, else the
 * double x.  0 on success, -1 on an HDF5 failure. */
int pd_h5_attr(hid_t obj, const char *name, const char *text, double x);

#endif
