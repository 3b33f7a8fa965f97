/* PNG pictures of one particle field: each particle a filled disc of its own size in the
 * frame [lo, hi] (y up), coloured by viridis; the walls as dark 2-pixel lines inside the
 * frame; the bodies filled light grey under the particles (a body's interior shows as
 * such where no particle covers it) and outlined like the walls over them; axes with tick
 * labels in metres along the frame's left and bottom edges; below
 * them a strip with the colour bar, its range, the field's name and unit and the time, in
 * a built-in 5x7 bitmap font. Optionally a second panel below, the same frame coloured by
 * particle size (log scale). Encoded by libpng (simplified API, into memory) and written
 * through rhod_write_bytes_atomic. */
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

/* A diverging map for signed fields (the vorticity), after Moreland's cool-warm: blue through
 * grey-white (0) to red, 9 evenly spaced stops. */
static const unsigned char coolwarm[9][3] = {{59, 76, 192},   {98, 130, 234},  {141, 176, 254},
                                             {184, 208, 249}, {221, 221, 221}, {245, 196, 173},
                                             {244, 154, 123}, {222, 96, 77},   {180, 4, 38}};

static void colour_at(double t, unsigned char rgb[3], int diverging) {
  const unsigned char(*map)[3] = diverging ? coolwarm : viridis;
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
    rgb[c] = (unsigned char)lround(map[k][c] + f * (map[k + 1][c] - map[k][c]));
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
    {'d', {0x01, 0x01, 0x0D, 0x13, 0x11, 0x11, 0x0F}},
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
    {'c', {0x00, 0x00, 0x0E, 0x10, 0x10, 0x11, 0x0E}},
    {'k', {0x10, 0x10, 0x12, 0x14, 0x18, 0x14, 0x12}},
    {'m', {0x00, 0x00, 0x1A, 0x15, 0x15, 0x11, 0x11}},
    {'x', {0x00, 0x00, 0x11, 0x0A, 0x04, 0x0A, 0x11}},
    {'y', {0x00, 0x00, 0x11, 0x11, 0x0F, 0x01, 0x0E}},
    {'v', {0x00, 0x00, 0x11, 0x11, 0x11, 0x0A, 0x04}},
    {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}},
    {'[', {0x0E, 0x08, 0x08, 0x08, 0x08, 0x08, 0x0E}},
    {']', {0x0E, 0x02, 0x02, 0x02, 0x02, 0x02, 0x0E}},
    {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
    {'^', {0x04, 0x0A, 0x11, 0x00, 0x00, 0x00, 0x00}},
};

static long text_width(const char *s, int scale) {
  size_t n = strlen(s);
  return n ? (long)n * 6 * scale - scale : 0;
}

static const glyph *glyph_of(char ch) {
  for (size_t k = 0; k < sizeof font / sizeof font[0]; k++)
    if (font[k].ch == ch)
      return &font[k];
  return NULL;
}

/* Draws s with its top-left corner at (x, y); characters without a glyph are blanks.
 * up: turned a quarter left, read from bottom to top (the letters' tops face left), with
 * (x, y) the bottom-left corner of the turned text. */
static void draw_text_turned(canvas *c, long x, long y, int scale, const char *s, int up) {
  static const unsigned char ink[3] = {0, 0, 0};
  for (long i = 0; *s; s++, i++) {
    const glyph *g = glyph_of(*s);
    if (!g)
      continue;
    for (int r = 0; r < 7; r++)
      for (int col = 0; col < 5; col++)
        if (g->rows[r] & (0x10 >> col))
          for (int dy = 0; dy < scale; dy++)
            for (int dx = 0; dx < scale; dx++) {
              const long along = (i * 6 + col) * scale + (up ? dy : dx);
              const long across = r * scale + (up ? dx : dy);
              if (up)
                put(c, x + across, y - 1 - along, ink);
              else
                put(c, x + along, y + across, ink);
            }
  }
}
static void draw_text(canvas *c, long x, long y, int scale, const char *s) {
  draw_text_turned(c, x, y, scale, s, 0);
}
static void draw_text_up(canvas *c, long x, long y, int scale, const char *s) {
  draw_text_turned(c, x, y, scale, s, 1);
}

/* ------------------------------------------------------------ particles */

/* The colour bar's label: the field's name and its unit. */
static const char *field_label(rhod_field f) {
  switch (f) {
  case RHOD_FIELD_PRESSURE:
    return "p [Pa]";
  case RHOD_FIELD_VELOCITY:
    return "|u| [m/s]";
  case RHOD_FIELD_DENSITY:
    return "rho [kg/m^3]";
  case RHOD_FIELD_SIZE:
    return "size [m]";
  case RHOD_FIELD_FREE_SURFACE:
    return "free surface [1]";
  case RHOD_FIELD_PHASE:
    return "phase [index]";
  case RHOD_FIELD_VORTICITY:
    return "vorticity [1/s]";
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
  case RHOD_FIELD_PHASE:
    return v->phase ? (double)v->phase[i] : 0.0;
  case RHOD_FIELD_VORTICITY:
    return (double)v->vort[i];
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
  case RHOD_FIELD_PHASE: /* NULL: one phase, every particle 0 */
    return 1;
  case RHOD_FIELD_VORTICITY:
    return v->vort != NULL;
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

int rhod_picture_field_range(const rhod_snapshot_view *v, rhod_field f, double range[2]) {
  range[0] = range[1] = 0.0;
  if (!v || (v->n > 0 && !field_present(v, f)) || (f == RHOD_FIELD_SIZE && v->n > 0 && !v->size))
    return -1;
  int any = 0;
  for (size_t i = 0; i < v->n; i++) {
    double x = field_value(v, f, i);
    if (!isfinite(x))
      continue;
    if (!any || x < range[0])
      range[0] = x;
    if (!any || x > range[1])
      range[1] = x;
    any = 1;
  }
  if (any && f == RHOD_FIELD_VORTICITY) { /* symmetric, zero in the middle of the map */
    const double m = fmax(fabs(range[0]), fabs(range[1]));
    range[0] = -m, range[1] = m;
  }
  return any ? 0 : -1;
}

/* ------------------------------------------------------------ layout and axes */

/* Sizes in pixels that follow the font's scale (1, 2 or 3 by the frame's width). */
typedef struct {
  int scale, pad, bar_h, text_h, ch, tick;
} metrics;

static metrics metrics_for(unsigned width) {
  int s = width >= 1200 ? 3 : width >= 600 ? 2 : 1;
  metrics m = {s, 3 * s, 8 * s, 7 * s, 6 * s, 4 * s};
  return m;
}

/* Ticks of one axis at k * step, k = k0 .. k0 + n - 1, labelled with `decimals`. */
typedef struct {
  double step;
  long k0;
  int n, decimals;
} ticks;

static void tick_label(char *buf, size_t len, const ticks *t, int i) {
  double v = (double)(t->k0 + i) * t->step;
  snprintf(buf, len, "%.*f", t->decimals, v);
}

/* Longest label of the ticks, in characters. */
static int tick_chars(const ticks *t) {
  int w = 0;
  for (int i = 0; i < t->n; i++) {
    char b[64];
    tick_label(b, sizeof b, t, i);
    int l = (int)strlen(b);
    if (l > w)
      w = l;
  }
  return w;
}

/* Round-number ticks (1, 2 or 5 times a power of ten) over [lo, hi], drawn on len pixels:
 * the finest step whose ticks stand at least `gap` pixels apart (x axis: gap 0, the
 * labels' width plus three characters). */
static ticks axis_ticks(double lo, double hi, double len, const metrics *m, int gap) {
  ticks t = {0, 0, 0, 0};
  const double span = hi - lo;
  if (!(span > 0) || !(len > 0))
    return t;
  double base = pow(10.0, floor(log10(span / 50.0)));
  static const double mult[3] = {1, 2, 5};
  for (int e = 0; e < 60; e++) {
    double step = base * mult[e % 3] * pow(10.0, e / 3);
    ticks c;
    c.step = step;
    c.k0 = (long)ceil(lo / step - 1e-9);
    long k1 = (long)floor(hi / step + 1e-9);
    c.n = k1 >= c.k0 ? (int)(k1 - c.k0 + 1) : 0;
    double lg = floor(log10(step) + 1e-9);
    c.decimals = lg < 0 ? (int)-lg : 0;
    if (c.decimals > 12)
      c.decimals = 12;
    double need = gap ? gap : (tick_chars(&c) + 3) * m->ch;
    if (c.n > 40)
      continue;
    t = c;
    if (step / span * len >= need || c.n <= 2)
      break;
  }
  return t;
}

/* The panel's layout: margins around the frame and the strips below it. */
typedef struct {
  metrics m;
  unsigned fh, left, right, top, below, panel_h;
  ticks tx, ty;
} layout;

static int make_layout(unsigned width, int panels, const double lo[2], const double hi[2],
                       layout *L, rhod_picture_geometry *g) {
  double ex = hi[0] - lo[0], ey = hi[1] - lo[1];
  if (!(ex > 0) || !(ey > 0) || !isfinite(ex) || !isfinite(ey) || width < 1 || width > MAX_SIDE)
    return -1;
  double fhd = floor(width * ey / ex + 0.5);
  if (!(fhd <= MAX_SIDE))
    return -1;
  L->fh = fhd < 1 ? 1u : (unsigned)fhd;
  L->m = metrics_for(width);
  const metrics *m = &L->m;
  L->tx = axis_ticks(lo[0], hi[0], width, m, 0);
  L->ty = axis_ticks(lo[1], hi[1], L->fh, m, 4 * m->text_h);
  /* left: "y [m]" turned, the tick labels, the ticks; right: half the widest x label */
  L->left =
      (unsigned)(m->pad + m->text_h + 2 * m->pad + tick_chars(&L->ty) * m->ch + m->pad + m->tick);
  int half = (tick_chars(&L->tx) * m->ch + 1) / 2;
  L->right = (unsigned)(half > m->pad ? half : m->pad);
  L->top = (unsigned)(m->text_h / 2 + m->pad);
  /* below: ticks, their labels, "x [m]"; the colour bar, then two lines of text */
  L->below = (unsigned)(m->tick + m->pad + m->text_h + m->pad + m->text_h + 2 * m->pad + m->bar_h +
                        m->pad + m->text_h + m->pad + m->text_h + m->pad);
  L->panel_h = L->top + L->fh + L->below;
  const double pw = (double)L->left + width + L->right, ph = (double)panels * L->panel_h;
  if (pw > MAX_SIDE || ph > MAX_SIDE)
    return -1;
  if (g) {
    g->frame_x = L->left;
    g->frame_y = L->top;
    g->frame_w = width;
    g->frame_h = L->fh;
    g->panel_h = L->panel_h;
    g->pic_w = (unsigned)pw;
    g->pic_h = (unsigned)ph;
    g->panels = (unsigned)panels;
  }
  return 0;
}

int rhod_picture_layout(unsigned width, int panels, const double lo[2], const double hi[2],
                        rhod_picture_geometry *g) {
  layout L;
  if (panels < 1)
    panels = 1;
  return make_layout(width, panels, lo, hi, &L, g);
}

/* ------------------------------------------------------------ walls */

static const unsigned char wall_ink[3] = {40, 40, 40};

/* Clips the segment p0-p1 to [x0, x1] x [y0, y1] (Liang-Barsky); 0 when nothing is left. */
static int clip(double p[2][2], double x0, double x1, double y0, double y1) {
  double t0 = 0, t1 = 1, dx = p[1][0] - p[0][0], dy = p[1][1] - p[0][1];
  const double q[4][2] = {
      {-dx, p[0][0] - x0}, {dx, x1 - p[0][0]}, {-dy, p[0][1] - y0}, {dy, y1 - p[0][1]}};
  for (int k = 0; k < 4; k++) {
    double pk = q[k][0], qk = q[k][1];
    if (pk == 0) {
      if (qk < 0)
        return 0;
    } else {
      double r = qk / pk;
      if (pk < 0 && r > t0)
        t0 = r;
      if (pk > 0 && r < t1)
        t1 = r;
    }
  }
  if (t0 > t1)
    return 0;
  double a[2] = {p[0][0] + t0 * dx, p[0][1] + t0 * dy};
  p[1][0] = p[0][0] + t1 * dx;
  p[1][1] = p[0][1] + t1 * dy;
  p[0][0] = a[0];
  p[0][1] = a[1];
  return 1;
}

/* A 2-pixel line along the segment (frame pixels, y down), kept inside the frame: a
 * wall on the frame's edge shows as its two outermost pixel rows or columns. */
static void thick_segment(canvas *f, unsigned fw, unsigned fh, double p[2][2]) {
  const double tol = 1e-6 * (fw + fh);
  if (!clip(p, -tol, fw + tol, -tol, fh + tol))
    return;
  for (int e = 0; e < 2; e++) {
    p[e][0] = fmin(fmax(p[e][0], 1.0), fw > 1 ? fw - 1.0 : 1.0);
    p[e][1] = fmin(fmax(p[e][1], 1.0), fh > 1 ? fh - 1.0 : 1.0);
  }
  double len = hypot(p[1][0] - p[0][0], p[1][1] - p[0][1]);
  long steps = (long)ceil(2 * len) + 1;
  for (long k = 0; k <= steps; k++) {
    double t = (double)k / (double)steps;
    double x = p[0][0] + t * (p[1][0] - p[0][0]), y = p[0][1] + t * (p[1][1] - p[0][1]);
    long i = (long)floor(x - 0.5), j = (long)floor(y - 0.5);
    for (long dj = 0; dj < 2; dj++)
      for (long di = 0; di < 2; di++)
        if (i + di >= 0 && i + di < (long)fw && j + dj >= 0 && j + dj < (long)fh)
          put(f, i + di, j + dj, wall_ink);
  }
}

/* The closed polygon pts[0 .. n - 1] (metres) as 2-pixel lines in the frame [lo, hi]. */
static void draw_ring(canvas *f, unsigned fw, unsigned fh, const double lo[2], const double hi[2],
                      const double (*pts)[2], size_t n) {
  const double sx = fw / (hi[0] - lo[0]), sy = fh / (hi[1] - lo[1]);
  for (size_t k = 0; k < n; k++) {
    const double *a = pts[k], *b = pts[(k + 1) % n];
    double p[2][2] = {{(a[0] - lo[0]) * sx, (hi[1] - a[1]) * sy},
                      {(b[0] - lo[0]) * sx, (hi[1] - b[1]) * sy}};
    if (isfinite(p[0][0]) && isfinite(p[0][1]) && isfinite(p[1][0]) && isfinite(p[1][1]))
      thick_segment(f, fw, fh, p);
  }
}

static void draw_walls(canvas *f, unsigned fw, unsigned fh, const double lo[2], const double hi[2],
                       const rhod_wall *walls, unsigned n_walls) {
  const double sx = fw / (hi[0] - lo[0]), sy = fh / (hi[1] - lo[1]);
  for (unsigned w = 0; w < n_walls; w++) {
    const rhod_shape *sh = &walls[w].shape;
    double rpx = sh->kind == RHOD_SHAPE_CIRCLE ? sh->radius * fmax(sx, sy) : 0;
    double nc = ceil(6.283185307179586 * rpx / 2);
    unsigned segs = nc < 32 ? 32u : nc > 4096 ? 4096u : (unsigned)nc;
    unsigned n = rhod_shape_outline(sh, segs, NULL);
    double(*pts)[2] = n ? malloc(sizeof(double[2]) * n) : NULL;
    if (!pts)
      continue; /* out of memory: the picture without this wall */
    rhod_shape_outline(sh, segs, pts);
    draw_ring(f, fw, fh, lo, hi, (const double(*)[2])pts, n);
    free(pts);
  }
}

/* ------------------------------------------------------------ bodies */

static const unsigned char body_fill[3] = {220, 220, 220};

/* Body k's outline: its points in view->body_xy (x, y interleaved). */
static const double (*body_ring(const rhod_snapshot_view *v, unsigned k, size_t *n))[2] {
  *n = v->body_start[k + 1] - v->body_start[k];
  return (const double(*)[2])(v->body_xy + 2 * (size_t)v->body_start[k]);
}

/* Fills each body's polygon light grey (even-odd rule, pixel centres), under the
 * particles: a row's crossings with the edges, sorted, pair by pair. -1: out of memory. */
static int fill_bodies(canvas *f, unsigned fw, unsigned fh, const double lo[2], const double hi[2],
                       const rhod_snapshot_view *v) {
  const double sx = fw / (hi[0] - lo[0]), sy = fh / (hi[1] - lo[1]);
  for (unsigned b = 0; b < v->n_bodies; b++) {
    size_t n;
    const double(*pts)[2] = body_ring(v, b, &n);
    if (n < 3)
      continue;
    double *px = malloc(sizeof(double) * 3 * n);
    if (!px)
      return -1;
    double *py = px + n, *cross = px + 2 * n;
    double ymin = INFINITY, ymax = -INFINITY;
    int finite = 1;
    for (size_t k = 0; k < n; k++) {
      px[k] = (pts[k][0] - lo[0]) * sx;
      py[k] = (hi[1] - pts[k][1]) * sy;
      finite &= isfinite(px[k]) && isfinite(py[k]);
      ymin = fmin(ymin, py[k]);
      ymax = fmax(ymax, py[k]);
    }
    /* clamped before the casts: the rows and columns inside the frame */
    long j0 = finite ? (long)fmin(fmax(floor(ymin - 0.5), 0.0), fh) : 0;
    long j1 = finite ? (long)fmin(fmax(ceil(ymax), -1.0), (double)fh - 1) : -1;
    for (long j = j0; j <= j1; j++) {
      const double yc = j + 0.5;
      size_t nc = 0;
      for (size_t k = 0; k < n; k++) {
        const size_t l = (k + 1) % n;
        if ((py[k] <= yc) != (py[l] <= yc)) {
          double x = px[k] + (yc - py[k]) * (px[l] - px[k]) / (py[l] - py[k]);
          size_t at = nc++; /* insertion sort: a row crosses an outline a few times */
          while (at > 0 && cross[at - 1] > x) {
            cross[at] = cross[at - 1];
            at--;
          }
          cross[at] = x;
        }
      }
      for (size_t c = 0; c + 1 < nc; c += 2) {
        /* the pixels whose centres lie in [cross[c], cross[c + 1]) */
        double a = fmin(fmax(ceil(cross[c] - 0.5), 0.0), fw);
        double e = fmin(fmax(ceil(cross[c + 1] - 0.5), 0.0), fw);
        for (long i = (long)a; i < (long)e; i++)
          put(f, i, j, body_fill);
      }
    }
    free(px);
  }
  return 0;
}

static void draw_bodies(canvas *f, unsigned fw, unsigned fh, const double lo[2], const double hi[2],
                        const rhod_snapshot_view *v) {
  for (unsigned b = 0; b < v->n_bodies; b++) {
    size_t n;
    const double(*pts)[2] = body_ring(v, b, &n);
    draw_ring(f, fw, fh, lo, hi, pts, n);
  }
}

/* ------------------------------------------------------------ panels */

/* The axes around the frame at (x0, y0) of fw x fh: a grey border, ticks and their labels
 * along the left and bottom edges, "x [m]" below and "y [m]" turned at the left. */
static void draw_axes(canvas *c, const layout *L, long x0, long y0, unsigned fw, const double lo[2],
                      const double hi[2]) {
  static const unsigned char border[3] = {160, 160, 160}, ink[3] = {0, 0, 0};
  const metrics *m = &L->m;
  const long fh = L->fh;
  for (long i = x0 - 1; i <= x0 + (long)fw; i++) {
    put(c, i, y0 - 1, border);
    put(c, i, y0 + fh, border);
  }
  for (long j = y0 - 1; j <= y0 + fh; j++) {
    put(c, x0 - 1, j, border);
    put(c, x0 + (long)fw, j, border);
  }
  char b[64];
  const double sx = fw / (hi[0] - lo[0]), sy = fh / (hi[1] - lo[1]);
  for (int k = 0; k < L->tx.n; k++) {
    double v = (double)(L->tx.k0 + k) * L->tx.step;
    long px = x0 + (long)floor((v - lo[0]) * sx);
    if (px >= x0 + (long)fw)
      px = x0 + (long)fw - 1;
    for (long j = y0 + fh + 1; j < y0 + fh + 1 + m->tick; j++)
      for (int d = 0; d < m->scale; d++)
        put(c, px + d - m->scale / 2, j, ink);
    tick_label(b, sizeof b, &L->tx, k);
    draw_text(c, px - text_width(b, m->scale) / 2, y0 + fh + 1 + m->tick + m->pad, m->scale, b);
  }
  const char *xt = "x [m]", *yt = "y [m]";
  draw_text(c, x0 + ((long)fw - text_width(xt, m->scale)) / 2,
            y0 + fh + 1 + m->tick + 2 * m->pad + m->text_h, m->scale, xt);
  for (int k = 0; k < L->ty.n; k++) {
    double v = (double)(L->ty.k0 + k) * L->ty.step;
    long py = y0 + (long)floor((hi[1] - v) * sy);
    if (py >= y0 + fh)
      py = y0 + fh - 1;
    for (long i = x0 - 1 - m->tick; i < x0 - 1; i++)
      for (int d = 0; d < m->scale; d++)
        put(c, i, py + d - m->scale / 2, ink);
    tick_label(b, sizeof b, &L->ty, k);
    draw_text(c, x0 - 1 - m->tick - m->pad - text_width(b, m->scale), py - m->text_h / 2, m->scale,
              b);
  }
  draw_text_up(c, m->pad, y0 + (fh + text_width(yt, m->scale)) / 2, m->scale, yt);
}

/* One panel at rows [y_off, y_off + panel_h): the particles coloured by `field` in the
 * frame [lo, hi], the walls, the axes, the colour bar with "min  label  max" and the
 * time (with the label when they do not fit on one line). -1: out of memory. */
static int draw_panel(canvas *c, long y_off, const layout *L, unsigned width,
                      const rhod_snapshot_view *v, rhod_field field, const double lo[2],
                      const double hi[2], const double *range, const rhod_wall *walls,
                      unsigned n_walls) {
  const metrics *m = &L->m;
  const unsigned fh = L->fh;
  double vmin = 0, vmax = 0;
  if (range) {
    vmin = range[0];
    vmax = range[1];
  } else {
    double r[2];
    rhod_picture_field_range(v, field, r);
    vmin = r[0];
    vmax = r[1];
  }
  /* the frame: a view of the canvas with its own origin, clipped to the frame */
  const long x0 = L->left, y0 = y_off + L->top;
  /* drawn into a frame-sized buffer, then copied in (the canvas rows are wider) */
  unsigned char *rows = malloc((size_t)3 * width * fh);
  if (!rows)
    return -1;
  memset(rows, 255, (size_t)3 * width * fh);
  canvas f = {rows, width, fh};
  const double ex = hi[0] - lo[0], ey = hi[1] - lo[1], sx = width / ex, sy = fh / ey;
  static const unsigned char grey[3] = {160, 160, 160};
  if (fill_bodies(&f, width, fh, lo, hi, v) != 0) {
    free(rows);
    return -1;
  }
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
      colour_at(scale_at(field, val, vmin, vmax), rgb, field == RHOD_FIELD_VORTICITY);
    disc(&f, fh, cx, cy, r, rgb);
  }
  draw_walls(&f, width, fh, lo, hi, walls, n_walls);
  draw_bodies(&f, width, fh, lo, hi, v);
  for (unsigned j = 0; j < fh; j++)
    memcpy(c->px + 3 * ((size_t)(y0 + j) * c->w + (size_t)x0), rows + (size_t)3 * width * j,
           (size_t)3 * width);
  free(rows);
  draw_axes(c, L, x0, y0, width, lo, hi);

  /* the colour bar under the frame's columns, then its text */
  long by = y0 + fh + 1 + m->tick + m->pad + m->text_h + m->pad + m->text_h + 2 * m->pad;
  long bx0 = x0, bx1 = x0 + (long)width;
  for (long i = bx0; i < bx1; i++) {
    unsigned char rgb[3];
    colour_at(bx1 - bx0 > 1 ? (double)(i - bx0) / (double)(bx1 - bx0 - 1) : 0.0, rgb,
              field == RHOD_FIELD_VORTICITY);
    for (long j = by; j < by + m->bar_h; j++)
      put(c, i, j, rgb);
  }
  long ty = by + m->bar_h + m->pad;
  char smin[32], smax[32], label[64], tline[192];
  fmt_value(smin, sizeof smin, vmin);
  fmt_value(smax, sizeof smax, vmax);
  snprintf(label, sizeof label, "%s%s", field_label(field),
           field == RHOD_FIELD_SIZE && vmin > 0 ? " (log)" : "");
  snprintf(tline, sizeof tline, "t = %.6g s", v->time);
  const int sc = m->scale;
  long wmin = text_width(smin, sc), wmax = text_width(smax, sc), wl = text_width(label, sc);
  draw_text(c, bx0, ty, sc, smin);
  if (bx1 - wmax > bx0 + wmin + 2 * sc)
    draw_text(c, bx1 - wmax, ty, sc, smax);
  long mx = x0 + ((long)width - wl) / 2;
  if (mx > bx0 + wmin + 2 * sc && mx + wl + 2 * sc < bx1 - wmax) {
    draw_text(c, mx, ty, sc, label);
  } else {
    char both[160];
    snprintf(both, sizeof both, "%.60s  %.96s", label, tline);
    snprintf(tline, sizeof tline, "%.180s", both);
  }
  long wt = text_width(tline, sc), tx = x0 + ((long)width - wt) / 2;
  if (tx < 0)
    tx = 0;
  draw_text(c, tx, ty + m->text_h + m->pad, sc, tline);
  return 0;
}

int rhod_write_picture(const char *path, const rhod_snapshot_view *v, rhod_field field,
                       int size_panel, unsigned width, const double lo[2], const double hi[2],
                       const double *range, const rhod_wall *walls, unsigned n_walls, char *err,
                       size_t errlen) {
  double ex = hi[0] - lo[0], ey = hi[1] - lo[1];
  if (!(ex > 0) || !(ey > 0) || !isfinite(ex) || !isfinite(ey)) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot draw: empty or invalid frame [%g, %g] x [%g, %g]", path,
               lo[0], hi[0], lo[1], hi[1]);
    return RHOD_ERR_SCENE;
  }
  const int panels = size_panel && field != RHOD_FIELD_SIZE ? 2 : 1;
  layout L;
  rhod_picture_geometry g;
  if (make_layout(width, panels, lo, hi, &L, &g) != 0) {
    if (err && errlen)
      snprintf(err, errlen,
               "%s: cannot draw: picture of a %u pixel wide frame of [%g, %g] x "
               "[%g, %g] outside 1..%u pixels",
               path, width, lo[0], hi[0], lo[1], hi[1], MAX_SIDE);
    return RHOD_ERR_SCENE;
  }
  if ((int)field < RHOD_FIELD_PRESSURE || (int)field > RHOD_FIELD_VORTICITY) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot draw: unknown field %d", path, field);
    return RHOD_ERR_SCENE;
  }
  if (v->n > 0 && (!v->x || !v->y || !v->size || !field_present(v, field))) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot draw: a particle field is missing", path);
    return RHOD_ERR_IO;
  }
  if (!walls)
    n_walls = 0;
  int bodies_ok = v->n_bodies == 0 || (v->body_start && v->body_start[0] == 0);
  for (unsigned k = 0; bodies_ok && k < v->n_bodies; k++)
    bodies_ok = v->body_start[k + 1] >= v->body_start[k];
  if (!bodies_ok || (v->n_bodies && v->body_start[v->n_bodies] && !v->body_xy)) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot draw: the outlines of the %u bodies are incomplete", path,
               v->n_bodies);
    return RHOD_ERR_IO;
  }

  /* Layout (make_layout): per panel, a top margin, the frame with the axes at its left
   * and bottom, the colour bar strip; with the size panel (paper 002 Figs. 11, 17, 19
   * show the sizes beside the fields) the same frame coloured by size below. */
  canvas c = {NULL, g.pic_w, g.pic_h};
  size_t bytes = (size_t)3 * c.w * c.h;
  c.px = malloc(bytes);
  if (!c.px) {
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot draw: out of memory", path);
    return RHOD_ERR_MEMORY;
  }
  memset(c.px, 255, bytes);
  int oom = draw_panel(&c, 0, &L, width, v, field, lo, hi, range, walls, n_walls) != 0;
  if (panels == 2 && !oom)
    oom = draw_panel(&c, (long)L.panel_h, &L, width, v, RHOD_FIELD_SIZE, lo, hi, NULL, walls,
                     n_walls) != 0;
  if (oom) {
    free(c.px);
    if (err && errlen)
      snprintf(err, errlen, "%s: cannot draw: out of memory", path);
    return RHOD_ERR_MEMORY;
  }

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
