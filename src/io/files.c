/* File-system questions the Fortran runtime cannot answer (lc_io_files): what kind of file a
 * path names without opening it (a FIFO blocks an open for reading until a writer comes),
 * fsync of a file and of a directory (a result is on disk before it replaces an older one,
 * and its new name after the rename), disk space reserved for a file before it is written,
 * and the space left on a file system (for messages), whether two paths name one file.
 * Each returns 0 or the C errno of the failure; none keeps state. */
#include <errno.h>
#include <fcntl.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

/* The kinds of lc_file_kind, as lc_io_files names them. */
enum { KIND_REGULAR = 0, KIND_DIRECTORY = 1, KIND_FIFO = 2, KIND_DEVICE = 3, KIND_SOCKET = 4, KIND_OTHER = 5 };

/* What `path` names, following symbolic links: *kind one of the kinds above; returns 0,
 * or errno (ENOENT: nothing there; ELOOP: a loop of symbolic links; EACCES: not searchable). */
int lc_file_kind(const char *path, int *kind) {
    struct stat info;
    if (stat(path, &info) != 0) return errno;
    if (S_ISREG(info.st_mode)) *kind = KIND_REGULAR;
    else if (S_ISDIR(info.st_mode)) *kind = KIND_DIRECTORY;
    else if (S_ISFIFO(info.st_mode)) *kind = KIND_FIFO;
    else if (S_ISCHR(info.st_mode) || S_ISBLK(info.st_mode)) *kind = KIND_DEVICE;
    else if (S_ISSOCK(info.st_mode)) *kind = KIND_SOCKET;
    else *kind = KIND_OTHER;
    return 0;
}

/* Whether the paths `a` and `b` name one file (the same device and inode, symbolic links
 * followed, `..` resolved by the system): *same 1 or 0; returns 0, or the errno of stat() of
 * either (ENOENT: one is not there, so they are not one file). */
int lc_same_file(const char *a, const char *b, int *same) {
    struct stat first, second;
    *same = 0;
    if (stat(a, &first) != 0) return errno;
    if (stat(b, &second) != 0) return errno;
    *same = first.st_dev == second.st_dev && first.st_ino == second.st_ino;
    return 0;
}

/* fsync `path` (a regular file or, with directory != 0, a directory): its data and size are
 * on the disk when this returns 0 (a file system that cannot sync a directory returns EINVAL:
 * taken as done). */
int lc_sync_path(const char *path, int directory) {
    int fd = open(path, directory ? (O_RDONLY | O_DIRECTORY) : O_RDONLY);
    int status = 0;
    if (fd < 0) return errno;
    if (fsync(fd) != 0 && !(directory && (errno == EINVAL || errno == EROFS))) status = errno;
    if (close(fd) != 0 && status == 0) status = errno;
    return status;
}

/* Allocate the disk blocks of the first `bytes` bytes of the file `path` (extending it to
 * that size if it is shorter), so that writes into them cannot fail for want of space (on
 * file systems that overwrite in place). Returns 0 or errno (ENOSPC: not enough space). */
int lc_reserve_space(const char *path, long long bytes) {
    int fd = open(path, O_WRONLY);
    int status;
    if (fd < 0) return errno;
    status = posix_fallocate(fd, 0, (off_t)bytes);
    if (close(fd) != 0 && status == 0) status = errno;
    return status;
}

/* Bytes an unprivileged writer may still add on the file system of `path`. */
int lc_free_bytes(const char *path, long long *bytes) {
    struct statvfs info;
    if (statvfs(path, &info) != 0) return errno;
    *bytes = (long long)info.f_bavail * (long long)info.f_frsize;
    return 0;
}

/* The C library's text for errno `code`, cut to `length` bytes (null-terminated). */
void lc_error_text(int code, char *text, int length) {
    if (length <= 0) return;
    strncpy(text, strerror(code), (size_t)length - 1);
    text[length - 1] = '\0';
}
