/* Shared by the output tests (test_io.c, test_output.c): a scratch folder and paths in
 * it, whole-file reads, particle arrays for snapshot views, PNG reading and the tree
 * removal at the end. Each test file fills its particles its own way (make_particles). */
#ifndef RHOD_TEST_IO_UTIL_H
#define RHOD_TEST_IO_UTIL_H

#include "rhod/io.h"

#include <ftw.h>
#include <png.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static char scratch[4096];

/* scratch/name, in one of 8 rotating buffers */
static char *spath(const char *name) {
  static char buf[8][4200];
  static int k;
  char *b = buf[k++ % 8];
  snprintf(b, sizeof buf[0], "%s/%s", scratch, name);
  return b;
}

/* A whole file, NUL-terminated (len: its length, may be NULL); NULL when unreadable. */
static char *slurp(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f)
    return NULL;
  size_t cap = 4096, n = 0;
  char *s = malloc(cap + 1);
  size_t r;
  while (s && (r = fread(s + n, 1, cap - n, f)) > 0) {
    n += r;
    if (n == cap) {
      char *t = realloc(s, 2 * cap + 1);
      if (!t) {
        free(s);
        s = NULL;
        break;
      }
      s = t;
      cap *= 2;
    }
  }
  fclose(f);
  if (s)
    s[n] = '\0';
  if (len)
    *len = n;
  return s;
}

static int count_of(const char *hay, const char *needle) {
  int n = 0;
  for (const char *p = strstr(hay, needle); p; p = strstr(p + 1, needle))
    n++;
  return n;
}

/* Particle arrays behind a snapshot view. */
typedef struct {
  size_t n;
  real *x, *y, *ux, *uy, *rho, *p, *m, *size;
  uint64_t *id;
  uint8_t *fs;
} particles;

/* Arrays for n particles (at least one element each), zeroed. */
static particles alloc_particles(size_t n) {
  particles P;
  P.n = n;
  size_t nn = n ? n : 1;
  real **arrays[] = {&P.x, &P.y, &P.ux, &P.uy, &P.rho, &P.p, &P.m, &P.size};
  for (size_t k = 0; k < 8; k++)
    *arrays[k] = calloc(nn, sizeof(real));
  P.id = calloc(nn, sizeof *P.id);
  P.fs = calloc(nn, 1);
  return P;
}

static void free_particles(particles *P) {
  real *arrays[] = {P->x, P->y, P->ux, P->uy, P->rho, P->p, P->m, P->size};
  for (size_t k = 0; k < 8; k++)
    free(arrays[k]);
  free(P->id);
  free(P->fs);
}

static rhod_snapshot_view view_of(const particles *P, double t) {
  rhod_snapshot_view v = {.time = t,
                          .n = P->n,
                          .x = P->x,
                          .y = P->y,
                          .ux = P->ux,
                          .uy = P->uy,
                          .rho = P->rho,
                          .p = P->p,
                          .m = P->m,
                          .size = P->size,
                          .id = P->id,
                          .fs = P->fs};
  return v;
}

/* A PNG as 8-bit RGB rows. */
typedef struct {
  unsigned w, h;
  unsigned char *px;
} rgb_image;

static int read_png(const char *path, rgb_image *im) {
  png_image img;
  memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&img, path))
    return 0;
  img.format = PNG_FORMAT_RGB;
  im->w = img.width;
  im->h = img.height;
  im->px = malloc(PNG_IMAGE_SIZE(img));
  if (!im->px || !png_image_finish_read(&img, NULL, im->px, 0, NULL)) {
    png_image_free(&img);
    free(im->px);
    im->px = NULL;
    return 0;
  }
  return 1;
}

/* nftw callback removing the scratch tree */
static int rm_entry(const char *path, const struct stat *st, int flag, struct FTW *ftw) {
  (void)st;
  (void)flag;
  (void)ftw;
  return remove(path);
}

#endif
