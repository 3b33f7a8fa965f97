/* Text outputs: atomic whole-file writes (path.tmp, fsync, rename) and the probes CSV,
 * which stays open and is flushed after every row. Every write is checked, so a full
 * disk is reported as "FILE: cannot write: No space left on device". */
#define _XOPEN_SOURCE 700 /* truncate */

#include "rhod/io.h"

#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int fail(char *err, size_t errlen, const char *path, int errnum) {
  if (err && errlen)
    snprintf(err, errlen, "%s: cannot write: %s", path, strerror(errnum));
  return RHOD_ERR_IO;
}

/* fsync the directory holding path so that the rename itself is durable. Best effort:
 * some file systems refuse fsync on a directory, which is not an error for us. */
static void sync_parent_dir(const char *path) {
  const char *slash = strrchr(path, '/');
  char *dir;
  if (!slash) {
    dir = strdup(".");
  } else if (slash == path) {
    dir = strdup("/");
  } else {
    size_t len = (size_t)(slash - path);
    dir = malloc(len + 1);
    if (dir) {
      memcpy(dir, path, len);
      dir[len] = '\0';
    }
  }
  if (!dir)
    return;
  int fd = open(dir, O_RDONLY | O_CLOEXEC);
  if (fd >= 0) {
    (void)fsync(fd);
    (void)close(fd);
  }
  free(dir);
}

int rhod_write_bytes_atomic(const char *path, const void *data, size_t len, char *err,
                            size_t errlen) {
  size_t plen = strlen(path);
  char *tmp = malloc(plen + 5);
  if (!tmp) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot write: out of memory", path);
    return RHOD_ERR_MEMORY;
  }
  memcpy(tmp, path, plen);
  memcpy(tmp + plen, ".tmp", 5);

  int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    int e = errno;
    free(tmp);
    return fail(err, errlen, path, e);
  }
  const unsigned char *p = data;
  size_t left = len;
  int e = 0;
  while (left > 0) {
    ssize_t w = write(fd, p, left);
    if (w < 0) {
      if (errno == EINTR)
        continue;
      e = errno;
      break;
    }
    if (w == 0) {
      e = EIO;
      break;
    }
    p += w;
    left -= (size_t)w;
  }
  if (!e && fsync(fd) != 0 && errno != EINVAL && errno != EROFS)
    e = errno;
  if (close(fd) != 0 && !e)
    e = errno;
  if (!e && rename(tmp, path) != 0)
    e = errno;
  if (e) {
    (void)unlink(tmp);
    free(tmp);
    return fail(err, errlen, path, e);
  }
  free(tmp);
  sync_parent_dir(path);
  return RHOD_OK;
}

/* Whole files in (scene text, checkpoints): io.h. Opened without blocking (a FIFO with
 * no writer must not hang the open), refused unless a regular file (a device such as
 * /dev/zero or a FIFO would be read forever), and never read past max bytes: a file that
 * grows while it is read is cut off there and refused as too large. */
int rhod_read_file(const char *path, size_t max, char **text, size_t *len) {
  int fd = open(path, O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0)
    return errno ? errno : EIO;
  struct stat st;
  if (fstat(fd, &st) != 0) {
    const int e = errno ? errno : EIO;
    (void)close(fd);
    return e;
  }
  if (!S_ISREG(st.st_mode)) {
    (void)close(fd);
    return S_ISDIR(st.st_mode) ? EISDIR : RHOD_READ_NOT_REGULAR;
  }
  if (st.st_size < 0 || (uint64_t)st.st_size > (uint64_t)max) {
    (void)close(fd);
    return RHOD_READ_TOO_LARGE;
  }
  /* room for the size fstat gave, plus one byte to see a file that grew */
  size_t cap = (size_t)st.st_size + 2, n = 0;
  if (cap < 64)
    cap = 64;
  char *buf = malloc(cap);
  int e = buf ? 0 : ENOMEM;
  while (!e) {
    if (n + 1 >= cap) {
      if (n > max) { /* grew past the limit while being read */
        e = RHOD_READ_TOO_LARGE;
        break;
      }
      size_t ncap = cap > SIZE_MAX / 2 ? SIZE_MAX : cap * 2;
      if (ncap > max + 2 && max + 2 > cap)
        ncap = max + 2;
      char *nb = realloc(buf, ncap);
      if (!nb) {
        e = ENOMEM;
        break;
      }
      buf = nb, cap = ncap;
    }
    const ssize_t got = read(fd, buf + n, cap - n - 1);
    if (got < 0) {
      if (errno == EINTR)
        continue;
      e = errno ? errno : EIO;
      break;
    }
    if (got == 0)
      break;
    n += (size_t)got;
  }
  (void)close(fd);
  if (!e && n > max)
    e = RHOD_READ_TOO_LARGE;
  if (e) {
    free(buf);
    return e;
  }
  buf[n] = '\0';
  *text = buf;
  *len = n;
  return 0;
}

const char *rhod_read_strerror(int e) {
  if (e == RHOD_READ_NOT_REGULAR)
    return "not a regular file";
  if (e == RHOD_READ_TOO_LARGE)
    return "too large";
  if (e == EISDIR)
    return "a directory, not a regular file";
  return strerror(e);
}

int rhod_write_file_atomic(const char *path, const char *text, char *err, size_t errlen) {
  return rhod_write_bytes_atomic(path, text, strlen(text), err, errlen);
}

/* A CSV field, quoted (RFC 4180) when it holds a comma, a quote or a line break. */
static int put_field(FILE *f, const char *s) {
  if (!strpbrk(s, ",\"\r\n"))
    return fputs(s, f) < 0 ? -1 : 0;
  if (fputc('"', f) == EOF)
    return -1;
  for (; *s; s++) {
    if (*s == '"' && fputc('"', f) == EOF)
      return -1;
    if (fputc(*s, f) == EOF)
      return -1;
  }
  return fputc('"', f) == EOF ? -1 : 0;
}

/* Flushes and checks the stream; on failure returns the errno to report. */
static int flush_check(FILE *f) {
  errno = 0;
  if (fflush(f) != 0 || ferror(f))
    return errno ? errno : EIO;
  return 0;
}

/* Clears c and keeps a copy of path for messages. */
static int csv_start(rhod_csv *c, const char *path, char *err, size_t errlen) {
  memset(c, 0, sizeof *c);
  c->path = strdup(path);
  if (!c->path) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot write: out of memory", path);
    return RHOD_ERR_MEMORY;
  }
  return RHOD_OK;
}

/* Ends an open: on error e (an errno) closes f, forgets the path and reports. */
static int csv_finish(rhod_csv *c, FILE *f, unsigned ncols, int e, char *err, size_t errlen) {
  if (e) {
    if (f)
      (void)fclose(f);
    const int rc = fail(err, errlen, c->path, e);
    free(c->path);
    c->path = NULL;
    return rc;
  }
  c->f = f;
  c->ncols = ncols;
  return RHOD_OK;
}

int rhod_csv_open(rhod_csv *c, const char *path, unsigned ncols, const char *const *names,
                  char *err, size_t errlen) {
  if (csv_start(c, path, err, errlen) != RHOD_OK)
    return RHOD_ERR_MEMORY;
  errno = 0;
  FILE *f = fopen(path, "w");
  if (!f)
    return csv_finish(c, NULL, ncols, errno ? errno : EIO, err, errlen);
  int e = 0;
  errno = 0;
  if (fputc('t', f) == EOF)
    e = errno ? errno : EIO;
  for (unsigned i = 0; i < ncols && !e; i++) {
    errno = 0;
    if (fputc(',', f) == EOF || put_field(f, names[i]) != 0)
      e = errno ? errno : EIO;
  }
  errno = 0;
  if (!e && fputc('\n', f) == EOF)
    e = errno ? errno : EIO;
  if (!e)
    e = flush_check(f);
  return csv_finish(c, f, ncols, e, err, errlen);
}

/* The fields of a CSV line (RFC 4180 quoting), or 0 when a quote is left open. */
static unsigned csv_fields(const char *s, size_t n) {
  unsigned k = 1;
  int q = 0;
  for (size_t i = 0; i < n; i++) {
    if (s[i] == '"')
      q = !q;
    else if (s[i] == ',' && !q)
      k++;
  }
  return q ? 0 : k;
}

static int csv_refuse(char *err, size_t errlen, const char *path, int rc, const char *fmt, ...) {
  if (err && errlen) {
    char msg[300];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    snprintf(err, errlen, "%s: %s", path, msg);
  }
  return rc;
}

/* Opens path (flags: O_RDONLY or O_RDWR, never blocking) and checks that it can be the
 * probes.csv a checkpoint recorded `bytes` of: a regular file at least that long, whose
 * first line is a header starting with t (of ncols probe columns, ncols >= 0) and whose
 * byte `bytes` ends a row. Returns the descriptor in *fd or an error (closed). */
static int csv_check_fd(const char *path, int flags, int ncols, uint64_t bytes, int *fd_out,
                        char *err, size_t errlen) {
  const int ck = RHOD_ERR_CHECKPOINT;
  const unsigned long long want = (unsigned long long)bytes;
  *fd_out = -1;
  if (bytes < 2 || bytes > (uint64_t)INT64_MAX)
    return csv_refuse(err, errlen, path, ck, "the checkpoint records an impossible length, %llu",
                      want);
  const int fd = open(path, flags | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) {
    const int e = errno ? errno : EIO;
    if (e == ENOENT)
      return csv_refuse(err, errlen, path, ck,
                        "missing (the checkpoint needs its first %llu bytes)", want);
    return csv_refuse(err, errlen, path, RHOD_ERR_IO, "cannot %s: %s",
                      flags == O_RDONLY ? "read" : "write", strerror(e));
  }
  struct stat st;
  int rc = RHOD_OK;
  char head[65536];
  ssize_t got;
  char last = 0;
  if (fstat(fd, &st) != 0) {
    rc = csv_refuse(err, errlen, path, RHOD_ERR_IO, "cannot read: %s", strerror(errno));
    goto out;
  }
  if (!S_ISREG(st.st_mode)) {
    rc = csv_refuse(err, errlen, path, ck, "not a regular file");
    goto out;
  }
  /* never lengthen it: ftruncate would pad a shorter file with NUL bytes */
  if ((uint64_t)st.st_size < bytes) {
    rc = csv_refuse(err, errlen, path, ck,
                    "%lld bytes, shorter than the %llu the checkpoint recorded",
                    (long long)st.st_size, want);
    goto out;
  }
  do
    got = pread(fd, head, bytes < sizeof head ? (size_t)bytes : sizeof head, 0);
  while (got < 0 && errno == EINTR);
  if (got < 0) {
    rc = csv_refuse(err, errlen, path, RHOD_ERR_IO, "cannot read: %s", strerror(errno));
    goto out;
  }
  const char *eol = memchr(head, '\n', (size_t)got);
  if (!eol || head[0] != 't' || (head[1] != ',' && head[1] != '\n') ||
      (ncols >= 0 && csv_fields(head, (size_t)(eol - head)) != (unsigned)ncols + 1)) {
    if (ncols >= 0)
      rc = csv_refuse(err, errlen, path, ck, "the header is not t and the %d probe columns", ncols);
    else
      rc = csv_refuse(err, errlen, path, ck, "the first line is not a header starting with t");
    goto out;
  }
  do
    got = pread(fd, &last, 1, (off_t)(bytes - 1));
  while (got < 0 && errno == EINTR);
  if (got != 1 || last != '\n')
    rc = csv_refuse(err, errlen, path, ck,
                    "byte %llu does not end a row (the file is not the checkpoint's)", want);
out:
  if (rc != RHOD_OK)
    (void)close(fd);
  else
    *fd_out = fd;
  return rc;
}

int rhod_csv_check(const char *path, uint64_t bytes, char *err, size_t errlen) {
  int fd;
  const int rc = csv_check_fd(path, O_RDONLY, -1, bytes, &fd, err, errlen);
  if (rc == RHOD_OK)
    (void)close(fd);
  return rc;
}

int rhod_csv_reopen(rhod_csv *c, const char *path, unsigned ncols, uint64_t bytes, char *err,
                    size_t errlen) {
  if (csv_start(c, path, err, errlen) != RHOD_OK)
    return RHOD_ERR_MEMORY;
  int fd = -1;
  int rc = ncols > 100000 ? csv_refuse(err, errlen, path, RHOD_ERR_CHECKPOINT, "%u columns", ncols)
                          : csv_check_fd(path, O_RDWR, (int)ncols, bytes, &fd, err, errlen);
  if (rc == RHOD_OK) {
    const int fl = fcntl(fd, F_GETFL);
    if (ftruncate(fd, (off_t)bytes) != 0 || lseek(fd, 0, SEEK_END) < 0 || fl < 0 ||
        fcntl(fd, F_SETFL, (fl & ~O_NONBLOCK) | O_APPEND) != 0)
      rc = csv_refuse(err, errlen, path, RHOD_ERR_IO, "cannot write: %s", strerror(errno));
  }
  FILE *f = NULL;
  if (rc == RHOD_OK) {
    errno = 0;
    if (!(f = fdopen(fd, "a")))
      rc = csv_refuse(err, errlen, path, RHOD_ERR_IO, "cannot write: %s",
                      strerror(errno ? errno : EIO));
  }
  if (rc != RHOD_OK) {
    if (fd >= 0)
      (void)close(fd);
    free(c->path);
    c->path = NULL;
    return rc;
  }
  return csv_finish(c, f, ncols, 0, err, errlen);
}

int rhod_csv_row(rhod_csv *c, double t, const double *values, char *err, size_t errlen) {
  if (!c->f) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot write: file not open", c->path ? c->path : "csv");
    return RHOD_ERR_IO;
  }
  int e = 0;
  errno = 0;
  if (fprintf(c->f, "%.9g", t) < 0)
    e = errno ? errno : EIO;
  for (unsigned i = 0; i < c->ncols && !e; i++) {
    errno = 0;
    if (fprintf(c->f, ",%.9g", values[i]) < 0)
      e = errno ? errno : EIO;
  }
  errno = 0;
  if (!e && fputc('\n', c->f) == EOF)
    e = errno ? errno : EIO;
  if (!e)
    e = flush_check(c->f);
  if (e)
    return fail(err, errlen, c->path, e);
  return RHOD_OK;
}

int rhod_csv_close(rhod_csv *c, char *err, size_t errlen) {
  int rc = RHOD_OK;
  if (c->f) {
    int e = flush_check(c->f);
    errno = 0;
    if (fclose(c->f) != 0 && !e)
      e = errno ? errno : EIO;
    if (e)
      rc = fail(err, errlen, c->path ? c->path : "csv", e);
  }
  free(c->path);
  memset(c, 0, sizeof *c);
  return rc;
}
