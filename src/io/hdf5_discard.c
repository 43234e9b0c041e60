/* Closing an HDF5 file that can no longer be written (lc_io_hdf5): HDF5 1.10 writes the
 * metadata it caches when a file is closed, and when that write fails (a full disk) it frees
 * the file but keeps its identifier; closing the library at exit then crashes on it. A result
 * file whose write failed is deleted anyway, so its descriptor is first pointed at an
 * anonymous file in memory: the closing writes succeed there, the close is clean, and the
 * memory goes with the descriptor. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>
#include <hdf5.h>

/* Point the descriptor of the open HDF5 file `file` (sec2 driver) at memory; returns 0, or
 * -1 when HDF5 gives no descriptor, or errno. */
int lc_hdf5_discard_file(hid_t file) {
    void *handle = NULL;
    int fd, sink;
    if (H5Fget_vfd_handle(file, H5P_DEFAULT, &handle) < 0 || handle == NULL) return -1;
    fd = *(int *)handle;
#ifdef MFD_CLOEXEC
    sink = memfd_create("layercontact-discarded-result", MFD_CLOEXEC);
#else
    sink = -1;
#endif
    if (sink < 0) sink = open("/dev/null", O_RDWR | O_CLOEXEC);
    if (sink < 0) return errno;
    if (dup2(sink, fd) < 0) {
        int code = errno;
        close(sink);
        return code;
    }
    close(sink);
    return 0;
}
