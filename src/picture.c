/* PNG pictures of one particle field: each particle a filled disc of its own size in the
 * frame [lo, hi] (y up), coloured by viridis; below the frame a strip with the colour bar,
 * its range and the time in a built-in 5x7 bitmap font. Optionally a second panel below,
 * the same frame coloured by particle size (log scale). Encoded by libpng (simplified
 * API, into memory) and written through rhod_write_bytes_atomic. */
#include "rhod/io.h"

#include <math.h>
#include <png.h>
#include <stdlib.h>
#include <string.h>

#define MAX_SIDE RHOD_PICTURE_MAX_SIDE /* the loader checks the same (scene.h) */

typedef struct {
  unsigned char *px; /* RGB, rows top to bottom */
  unsigned w, h;
} canvas;

static void put(canvas *c, long x, long y, const unsigned char rgb[3]) {
  if (x < 0 || y < 0 || x >= (long)c->w || y >= (long)c->h)
    return;
  unsigned char *p = c->px + 3 * ((size_t)y * c->w + (size_t)x);
  p[0] = rgb[0];
  p[1] = rgb[1];
  p[2] = rgb[2];
}

/* ------------------------------------------------------------ colour map */

/* viridis (matplotlib), 9 evenly spaced stops, interpolated linearly. */
static const unsigned char viridis[9][3] = {{68, 1, 84},    {71, 45, 123},  {59, 82, 139},
                                            {44, 114, 142}, {33, 144, 140}, {39, 173, 129},
                                            {93, 200, 99},  {170, 220, 50}, {253, 231, 37}};

static void colour_at(double t, unsigned char rgb[3]) {
  if (!(t > 0))
    t = 0; /* also NaN */
  if (t > 1)
    t = 1;
  double s = t * 8;
  int k = (int)s;
  if (k > 7)
    k = 7;
  double f = s - k;
  for (int c = 0; c < 3; c++)
    rgb[c] = (unsigned char)lround(viridis[k][c] + f * (viridis[k + 1][c] - viridis[k][c]));
}

/* ------------------------------------------------------------ 5x7 font */

typedef struct {
  char ch;
  unsigned char rows[7]; /* bit 4 is the leftmost column */
} glyph;

static const glyph font[] = {
    {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}},
    {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}},
    {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
    {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}},
    {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
    {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}},
    {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
    {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}},
    {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
    {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}},
    {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
    {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
    {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}},
    {'|', {0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
    {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
    {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
    {'g', {0x00, 0x0F, 0x11, 0x11, 0x0F, 0x01, 0x0E}},
    {'l', {0x0C, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}},
    {'a', {0x00, 0x00, 0x0E, 0x01, 0x0F, 0x11, 0x0F}},
    {'e', {0x00, 0x00, 0x0E, 0x11, 0x1F, 0x10, 0x0E}},
    {'f', {0x06, 0x09, 0x08, 0x1C, 0x08, 0x08, 0x08}},
    {'h', {0x10, 0x10, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'i', {0x04, 0x00, 0x0C, 0x04, 0x04, 0x04, 0x0E}},
    {'n', {0x00, 0x00, 0x16, 0x19, 0x11, 0x11, 0x11}},
    {'o', {0x00, 0x00, 0x0E, 0x11, 0x11, 0x11, 0x0E}},
    {'p', {0x00, 0x00, 0x1E, 0x11, 0x1E, 0x10, 0x10}},
    {'r', {0x00, 0x00, 0x16, 0x19, 0x10, 0x10, 0x10}},
    {'s', {0x00, 0x00, 0x0F, 0x10, 0x0E, 0x01, 0x1E}},
    {'t', {0x08, 0x08, 0x1C, 0x08, 0x08, 0x09, 0x06}},
    {'u', {0x00, 0x00, 0x11, 0x11, 0x11, 0x13, 0x0D}},
    {'z', {0x00, 0x00, 0x1F, 0x02, 0x04, 0x08, 0x1F}},
};

static long text_width(const char *s, int scale) {
  size_t n = strlen(s);
  return n ? (long)n * 6 * scale - scale : 0;
}

/* Draws s with its top-left corner at (x, y); characters without a glyph are blanks. */
static void draw_text(canvas *c, long x, long y, int scale, const char *s) {
  static const unsigned char ink[3] = {0, 0, 0};
  for (; *s; s++, x += 6 * scale) {
    const glyph *g = NULL;
    for (size_t k = 0; k < sizeof font / sizeof font[0]; k++)
      if (font[k].ch == *s)
        g = &font[k];
    if (!g)
      continue;
    for (int r = 0; r < 7; r++)
      for (int col = 0; col < 5; col++)
        if (g->rows[r] & (0x10 >> col))
          for (int dy = 0; dy < scale; dy++)
            for (int dx = 0; dx < scale; dx++)
              put(c, x + col * scale + dx, y + r * scale + dy, ink);
  }
}

/* ------------------------------------------------------------ particles */

static const char *field_label(rhod_field f) {
  switch (f) {
  case RHOD_FIELD_PRESSURE:
    return "p";
  case RHOD_FIELD_VELOCITY:
    return "|u|";
  case RHOD_FIELD_DENSITY:
    return "rho";
  case RHOD_FIELD_SIZE:
    return "size";
  case RHOD_FIELD_FREE_SURFACE:
    return "fs";
  }
  return "";
}

static double field_value(const rhod_snapshot_view *v, rhod_field f, size_t i) {
  switch (f) {
  case RHOD_FIELD_PRESSURE:
    return (double)v->p[i];
  case RHOD_FIELD_VELOCITY:
    return hypot((double)v->ux[i], (double)v->uy[i]);
  case RHOD_FIELD_DENSITY:
    return (double)v->rho[i];
  case RHOD_FIELD_SIZE:
    return (double)v->size[i];
  case RHOD_FIELD_FREE_SURFACE:
    return v->fs ? (double)v->fs[i] : 0.0;
  }
  return 0.0;
}

/* Whether the arrays the field needs are there (fs may be NULL: every particle inner). */
static int field_present(const rhod_snapshot_view *v, rhod_field f) {
  switch (f) {
  case RHOD_FIELD_PRESSURE:
    return v->p != NULL;
  case RHOD_FIELD_VELOCITY:
    return v->ux && v->uy;
  case RHOD_FIELD_DENSITY:
    return v->rho != NULL;
  case RHOD_FIELD_SIZE:
    return 1;
  case RHOD_FIELD_FREE_SURFACE:
    return 1;
  }
  return 0;
}

/* Fills the pixels that the disc of radius r (pixels) around (cx, cy) touches, clipped to
 * the frame (rows < fh); at least the pixel holding the centre. Counting every touched
 * pixel (rather than only those whose centre is inside) keeps a lattice of discs a
 * couple of pixels wide from showing the background between them. */
static void disc(canvas *c, unsigned fh, double cx, double cy, double r,
                 const unsigned char rgb[3]) {
  long j0 = (long)floor(cy - r), j1 = (long)ceil(cy + r) - 1;
  if (j1 < j0)
    j1 = j0;
  if (j0 < 0)
    j0 = 0;
  if (j1 >= (long)fh)
    j1 = (long)fh - 1;
  for (long j = j0; j <= j1; j++) {
    double dy = j > cy ? j - cy : (j + 1 < cy ? cy - (j + 1) : 0.0);
    double w2 = r * r - dy * dy;
    if (w2 < 0)
      continue;
    double w = sqrt(w2);
    long i0 = (long)floor(cx - w), i1 = (long)ceil(cx + w) - 1;
    if (i1 < i0)
      i1 = i0;
    if (i0 < 0)
      i0 = 0;
    if (i1 >= (long)c->w)
      i1 = (long)c->w - 1;
    if (i0 > i1)
      continue;
    unsigned char *p = c->px + 3 * ((size_t)j * c->w + (size_t)i0);
    for (long i = i0; i <= i1; i++, p += 3) {
      p[0] = rgb[0];
      p[1] = rgb[1];
      p[2] = rgb[2];
    }
  }
}

static void fmt_value(char *buf, size_t len, double x) { snprintf(buf, len, "%.4g", x); }

/* Where a value falls on the colour scale [vmin, vmax]: linear, or logarithmic for the
 * particle size (levels are dx / e^l: equal steps of colour per level). */
static double scale_at(rhod_field field, double f, double vmin, double vmax) {
  if (field == RHOD_FIELD_SIZE && vmin > 0 && vmax > vmin && f > 0)
    return log(f / vmin) / log(vmax / vmin);
  return vmax != vmin ? (f - vmin) / (vmax - vmin) : 0.0;
}

/* One panel at rows [y_off, y_off + fh + strip): the particles coloured by `field` in the
 * frame [lo, hi], a grey rule, the colour bar and "min  field  t=...s  max". */
static void draw_panel(canvas *c, long y_off, unsigned fh, int scale, const rhod_snapshot_view *v,
                       rhod_field field, const double lo[2], const double hi[2],
                       const double *range) {
  const unsigned width = c->w;
  /* Field values and their range. */
  double vmin = 0, vmax = 0;
  if (range) {
    vmin = range[0];
    vmax = range[1];
  } else {
    int any = 0;
    for (size_t i = 0; i < v->n; i++) {
      double f = field_value(v, field, i);
      if (!isfinite(f))
        continue;
      if (!any || f < vmin)
        vmin = f;
      if (!any || f > vmax)
        vmax = f;
      any = 1;
    }
  }
  /* the frame, drawn into a view of the canvas that starts at row y_off */
  canvas f = {c->px + 3 * (size_t)y_off * width, width, c->h - (unsigned)y_off};
  const double ex = hi[0] - lo[0], ey = hi[1] - lo[1], sx = width / ex, sy = fh / ey;
  static const unsigned char grey[3] = {160, 160, 160};
  for (size_t i = 0; i < v->n; i++) {
    double cx = ((double)v->x[i] - lo[0]) * sx, cy = (hi[1] - (double)v->y[i]) * sy;
    if (!isfinite(cx) || !isfinite(cy))
      continue;
    double r = 0.5 * (double)v->size[i] * sx;
    if (!(r > 0))
      r = 0;
    if (r > 2.0 * (width + fh)) /* covers the frame already; keeps the pixel maths finite */
      r = 2.0 * (width + fh);
    if (cx + r < 0 || cy + r < 0 || cx - r > width || cy - r > fh)
      continue;
    double val = field_value(v, field, i);
    unsigned char rgb[3];
    if (!isfinite(val))
      memcpy(rgb, grey, 3);
    else
      colour_at(scale_at(field, val, vmin, vmax), rgb);
    disc(&f, fh, cx, cy, r, rgb);
  }

  /* The strip: a rule, the colour bar, then "min   field  t=...s   max". */
  int pad = 3 * scale, bar_h = 8 * scale;
  static const unsigned char rule[3] = {200, 200, 200};
  for (unsigned i = 0; i < width; i++)
    put(&f, i, fh, rule);
  long y0 = (long)fh + 1 + pad, x0 = pad, x1 = (long)width - pad;
  if (x1 <= x0) {
    x0 = 0;
    x1 = width;
  }
  for (long i = x0; i < x1; i++) {
    unsigned char rgb[3];
    colour_at(x1 - x0 > 1 ? (double)(i - x0) / (double)(x1 - x0 - 1) : 0.0, rgb);
    for (long j = y0; j < y0 + bar_h; j++)
      put(&f, i, j, rgb);
  }
  long ty = y0 + bar_h + pad;
  char smin[32], smax[32], mid[64];
  fmt_value(smin, sizeof smin, vmin);
  fmt_value(smax, sizeof smax, vmax);
  snprintf(mid, sizeof mid, "%s%s  t=%.6gs", field_label(field),
           field == RHOD_FIELD_SIZE && vmin > 0 ? " (log)" : "", v->time);
  long wmin = text_width(smin, scale), wmax = text_width(smax, scale);
  long wmid = text_width(mid, scale);
  draw_text(&f, x0, ty, scale, smin);
  if (x1 - wmax > x0 + wmin + 2 * scale)
    draw_text(&f, x1 - wmax, ty, scale, smax);
  long mx = ((long)width - wmid) / 2;
  if (mx > x0 + wmin + 2 * scale && mx + wmid + 2 * scale < x1 - wmax)
    draw_text(&f, mx, ty, scale, mid);
}

int rhod_write_picture(const char *path, const rhod_snapshot_view *v, rhod_field field,
                       int size_panel, unsigned width, const double lo[2], const double hi[2],
                       const double *range, char *err, size_t errlen) {
  double ex = hi[0] - lo[0], ey = hi[1] - lo[1];
  if (!(ex > 0) || !(ey > 0) || !isfinite(ex) || !isfinite(ey)) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot draw: empty or invalid frame [%g, %g] x [%g, %g]", path,
               lo[0], hi[0], lo[1], hi[1]);
    return RHOD_ERR_SCENE;
  }
  const unsigned panels = size_panel && field != RHOD_FIELD_SIZE ? 2 : 1;
  double fhd = floor(width * ey / ex + 0.5);
  if (width < 1 || width > MAX_SIDE || !(fhd * panels <= MAX_SIDE)) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot draw: picture size %u x %.0f outside 1..%u", path, width,
               fhd * panels, MAX_SIDE);
    return RHOD_ERR_SCENE;
  }
  if ((int)field < RHOD_FIELD_PRESSURE || (int)field > RHOD_FIELD_FREE_SURFACE) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot draw: unknown field %d", path, field);
    return RHOD_ERR_SCENE;
  }
  if (v->n > 0 && (!v->x || !v->y || !v->size || !field_present(v, field))) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot draw: a particle field is missing", path);
    return RHOD_ERR_IO;
  }
  unsigned fh = fhd < 1 ? 1u : (unsigned)fhd;

  /* Layout: per panel, frame rows [0, fh), a grey rule, then the strip; with the size
   * panel (paper 002 Figs. 11, 17, 19 show the sizes beside the fields) the same frame
   * coloured by size below the field's. */
  int scale = width >= 1200 ? 3 : width >= 600 ? 2 : 1;
  int pad = 3 * scale, bar_h = 8 * scale, text_h = 7 * scale;
  unsigned strip = (unsigned)(1 + pad + bar_h + pad + text_h + pad);
  canvas c = {NULL, width, panels * (fh + strip)};
  size_t bytes = (size_t)3 * c.w * c.h;
  c.px = malloc(bytes);
  if (!c.px) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot draw: out of memory", path);
    return RHOD_ERR_MEMORY;
  }
  memset(c.px, 255, bytes);
  draw_panel(&c, 0, fh, scale, v, field, lo, hi, range);
  if (panels == 2)
    draw_panel(&c, (long)(fh + strip), fh, scale, v, RHOD_FIELD_SIZE, lo, hi, NULL);

  /* Encode into memory, then write atomically. */
  png_image img;
  memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  img.width = c.w;
  img.height = c.h;
  img.format = PNG_FORMAT_RGB;
  png_alloc_size_t cap = PNG_IMAGE_PNG_SIZE_MAX(img), len = cap;
  void *mem = malloc(cap);
  int rc = RHOD_OK;
  if (!mem) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot draw: out of memory", path);
    rc = RHOD_ERR_MEMORY;
  } else if (!png_image_write_to_memory(&img, mem, &len, 0, c.px, 0, NULL)) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot encode PNG: %s", path, img.message);
    png_image_free(&img);
    rc = RHOD_ERR_IO;
  } else {
    rc = rhod_write_bytes_atomic(path, mem, len, err, errlen);
  }
  free(mem);
  free(c.px);
  return rc;
}
