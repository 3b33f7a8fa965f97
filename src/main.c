/* rhod: command line. The only place that prints to the terminal and exits. */
#define _XOPEN_SOURCE 700 /* realpath, sigaction types */
#include "rhod/checkpoint.h"
#include "rhod/io.h"
#include "rhod/scene.h"
#include "rhod/sim.h"
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define ERRLEN 1024

static const char *USAGE =
    "usage: rhod run SCENE [-o OUT] [--set dotted.key=value]... [--checkpoint-every T]\n"
    "       rhod resume OUT\n"
    "       rhod --help | --version\n"
    "Runs the scene and writes snapshots (HDF5 + XDMF), pictures (PNG), probes.csv,\n"
    "summary.json and run.log to OUT (default out/<scene file's folder name>).\n"
    "--checkpoint-every T writes OUT/checkpoint.rhod every T simulated seconds; SIGINT or\n"
    "SIGTERM writes one and stops. `rhod resume OUT` continues from it, bit for bit.\n"
    "Exit codes: 0 ok, 2 usage, 3 unreadable scene, 4 invalid scene, 5 output folder,\n"
    "6 unstable run, 7 write error during the run, 8 out of memory, 9 interrupted\n"
    "(checkpoint written), 10 bad or unfitting checkpoint.\n";

/* SIGINT/SIGTERM: the loop stops after the step in progress, writes a checkpoint and
 * exits with RHOD_ERR_INTERRUPTED. */
static volatile sig_atomic_t g_stop;
static void on_signal(int sig) { g_stop = sig; }

static FILE *g_log;

static void logline(const char *fmt, ...) {
  char buf[2048];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  printf("%s\n", buf);
  fflush(stdout);
  if (g_log) {
    fprintf(g_log, "%s\n", buf);
    fflush(g_log);
  }
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int mkdir_p(const char *path) {
  char tmp[4096];
  snprintf(tmp, sizeof tmp, "%s", path);
  for (char *q = tmp + 1; *q; q++)
    if (*q == '/') {
      *q = 0;
      if (mkdir(tmp, 0755) != 0 && errno != EEXIST)
        return -1;
      *q = '/';
    }
  if (mkdir(tmp, 0755) != 0 && errno != EEXIST)
    return -1;
  struct stat st;
  if (stat(tmp, &st) != 0 || !S_ISDIR(st.st_mode)) {
    errno = ENOTDIR;
    return -1;
  }
  return 0;
}

static int check_output_dir(const char *out, char *err, size_t len) {
  if (mkdir_p(out) != 0) {
    snprintf(err, len, "%.900s: cannot create output folder: %s", out, strerror(errno));
    return RHOD_ERR_OUTPUT;
  }
  char probe[4200];
  snprintf(probe, sizeof probe, "%s/.rhod_write_test", out);
  FILE *f = fopen(probe, "w");
  if (!f || fputs("x", f) < 0 || fclose(f) != 0) {
    snprintf(err, len, "%.900s: output folder is not writable: %s", out, strerror(errno));
    return RHOD_ERR_OUTPUT;
  }
  remove(probe);
  return RHOD_OK;
}

static void fmt_hms(double s, char *buf, size_t len) {
  if (!isfinite(s) || s < 0)
    s = 0;
  long t = (long)(s + 0.5);
  snprintf(buf, len, "%02ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
}

typedef struct {
  const char *out;
  rhod_scene *sc;
  rhod_sim sim;
  rhod_param_list params;
  rhod_csv csv;
  int csv_open;
  int nsnap, snap_cap;
  double *snap_t;
  size_t *snap_n;
  double *probe_vals;
  unsigned nprobe_cols;
  const char *probe_names[RHOD_PROBE_COLUMNS_TOTAL];
  char probe_buf[RHOD_PROBE_COLUMNS_TOTAL][RHOD_PROBE_NAME_MAX];
  char where[256];
  /* checkpoints */
  const char *scene_arg;
  const char **sets;
  int nsets;
  double ck_every, next_ck;
  long step0; /* steps done before this process (a resume) */
} run_ctx;

/* OUT/checkpoint.rhod: the state at the top of the loop, after the outputs of time t. */
static int write_checkpoint(run_ctx *c, double next_out, double next_probe, char *err, size_t len) {
  rhod_checkpoint ck;
  memset(&ck, 0, sizeof ck);
  ck.t = c->sim.t;
  ck.next_out = next_out;
  ck.next_probe = next_probe;
  ck.next_checkpoint = c->next_ck;
  ck.checkpoint_every = c->ck_every;
  ck.step = c->sim.step;
  ck.reflected = c->sim.reflected;
  ck.splits = c->sim.apr.split_total;
  ck.merges = c->sim.apr.merged_total;
  ck.absorbed = c->sim.apr.absorbed_total;
  ck.ke_merged = c->sim.apr.ke_merged;
  ck.ke_absorbed = c->sim.apr.ke_absorbed;
  ck.stiffness = c->sim.sph.st_lambda;
  long pos = c->csv.f ? ftell(c->csv.f) : -1;
  ck.probes_bytes = pos > 0 ? (uint64_t)pos : 0;
  ck.nsnap = c->nsnap;
  ck.snap_t = c->snap_t;
  uint64_t *sn = malloc(sizeof(uint64_t) * (size_t)(c->nsnap + 1));
  if (!sn) {
    snprintf(err, len, "out of memory writing a checkpoint");
    return RHOD_ERR_MEMORY;
  }
  for (int i = 0; i < c->nsnap; i++)
    sn[i] = c->snap_n[i];
  ck.snap_n = sn;
  ck.scene_path = (char *)c->scene_arg;
  ck.nsets = c->nsets;
  ck.sets = (char **)c->sets;
  ck.params = c->params;
  char path[4200];
  snprintf(path, sizeof path, "%s/checkpoint.rhod", c->out);
  int st = rhod_checkpoint_write(path, &ck, &c->sim.p, err, len);
  free(sn);
  return st;
}

static int write_output(run_ctx *c, char *err, size_t len) {
  rhod_sim *s = &c->sim;
  rhod_snapshot_view v;
  rhod_sim_fetch(s, &v);
  int st = rhod_write_snapshot(c->out, c->nsnap, &v, &c->params, err, len);
  if (st != RHOD_OK)
    return st;
  if (c->nsnap >= c->snap_cap) {
    c->snap_cap = 2 * c->snap_cap + 16;
    c->snap_t = realloc(c->snap_t, sizeof(double) * (size_t)c->snap_cap);
    c->snap_n = realloc(c->snap_n, sizeof(size_t) * (size_t)c->snap_cap);
    if (!c->snap_t || !c->snap_n)
      return RHOD_ERR_MEMORY;
  }
  c->snap_t[c->nsnap] = s->t;
  c->snap_n[c->nsnap] = s->p.n;
  c->nsnap++;
  st = rhod_write_xdmf(c->out, c->nsnap, c->snap_t, c->snap_n, err, len);
  if (st != RHOD_OK)
    return st;
  char png[4200];
  snprintf(png, sizeof png, "%s/snapshot_%04d.png", c->out, c->nsnap - 1);
  const rhod_scene *sc = c->sc;
  const double *lo = sc->picture_box_set ? sc->picture_box_min : s->lo;
  const double *hi = sc->picture_box_set ? sc->picture_box_max : s->hi;
  st = rhod_write_picture(png, &v, sc->picture_field, sc->picture_size_panel, sc->picture_width, lo,
                          hi, sc->picture_range_set ? sc->picture_range : NULL, err, len);
  return st;
}

static int write_summary(run_ctx *c, const char *status, const char *cause, double wall) {
  rhod_sim *s = &c->sim;
  char buf[16384];
  size_t o = 0;
  const double psteps = s->particle_steps;
  o += (size_t)snprintf(buf + o, sizeof buf - o,
                        "{\n  \"status\": \"%s\",\n  \"cause\": \"%s\",\n  \"scene\": \"%s\",\n"
                        "  \"particles\": %zu,\n  \"steps\": %ld,\n  \"time\": %.9g,\n"
                        "  \"dt\": %.9g,\n  \"wall_seconds\": %.6g,\n"
                        "  \"us_per_particle_step\": %.6g,\n  \"precision\": \"%s\",\n"
                        "  \"threads\": %d,\n  \"kernels_ran_on\": \"%s\",\n"
                        "  \"wall_reflections\": %ld,\n  \"splits\": %ld,\n  \"merges\": %ld,\n"
                        "  \"absorbed\": %ld,\n  \"merge_dissipation\": %.9g,\n"
                        "  \"absorb_dissipation\": %.9g,\n"
                        "  \"damper_limited_steps\": %ld,\n  \"stiffness_limited_steps\": %ld,\n"
                        "  \"probes\": {",
                        status, cause, c->sc->path, s->p.n, s->step, s->t, s->dt, wall,
                        psteps > 0 ? 1e6 * wall / psteps : 0.0, RHOD_REAL_NAME,
                        omp_get_max_threads(), c->where, s->reflected, s->apr.split_total,
                        s->apr.merged_total, s->apr.absorbed_total, s->apr.ke_merged,
                        s->apr.ke_absorbed, s->damper_limited, s->stiffness_limited);
  for (unsigned k = 0; k < c->nprobe_cols && o < sizeof buf - 200; k++)
    o += (size_t)snprintf(buf + o, sizeof buf - o, "%s\n    \"%s\": %.9g", k ? "," : "",
                          c->probe_names[k], c->probe_vals ? c->probe_vals[k] : 0.0);
  o += (size_t)snprintf(buf + o, sizeof buf - o, "%s}\n}\n", c->nprobe_cols ? "\n  " : "");
  char path[4200], err[ERRLEN];
  snprintf(path, sizeof path, "%s/summary.json", c->out);
  int st = rhod_write_file_atomic(path, buf, err, sizeof err);
  if (st != RHOD_OK)
    fprintf(stderr, "rhod: %s\n", err);
  return st;
}

static int cmd_run(int argc, char **argv, const char *resume_out) {
  const char *scene = NULL, *out = NULL;
  const char *sets[256];
  int nsets = 0;
  double ck_every = 0;
  rhod_checkpoint ck;
  memset(&ck, 0, sizeof ck);
  char err[ERRLEN] = "";
  if (resume_out) {
    char path[4200];
    snprintf(path, sizeof path, "%s/checkpoint.rhod", resume_out);
    int st = rhod_checkpoint_read(path, &ck, err, sizeof err);
    if (st == RHOD_OK) { /* probes.csv as long as recorded: refused before anything is written */
      snprintf(path, sizeof path, "%s/probes.csv", resume_out);
      if ((st = rhod_csv_check(path, ck.probes_bytes, err, sizeof err)) != RHOD_OK)
        rhod_checkpoint_free(&ck);
    }
    if (st != RHOD_OK) {
      fprintf(stderr, "rhod: %s\n", err);
      return st;
    }
    scene = ck.scene_path;
    out = resume_out;
    nsets = ck.nsets < 256 ? ck.nsets : 256;
    for (int i = 0; i < nsets; i++)
      sets[i] = ck.sets[i];
    ck_every = ck.checkpoint_every;
  }
  for (int i = 0; i < argc; i++) {
    if (!strcmp(argv[i], "-o") || !strcmp(argv[i], "--output")) {
      if (++i >= argc) {
        fprintf(stderr, "rhod: -o needs a folder\n%s", USAGE);
        return RHOD_ERR_USAGE;
      }
      out = argv[i];
    } else if (!strcmp(argv[i], "--set")) {
      if (++i >= argc || !strchr(argv[i], '=')) {
        fprintf(stderr, "rhod: --set needs dotted.key=value\n%s", USAGE);
        return RHOD_ERR_USAGE;
      }
      if (nsets >= 256) {
        fprintf(stderr, "rhod: too many --set options (256 at most)\n");
        return RHOD_ERR_USAGE;
      }
      sets[nsets++] = argv[i];
    } else if (!strcmp(argv[i], "--checkpoint-every")) {
      char *end = NULL;
      ck_every = ++i < argc ? strtod(argv[i], &end) : 0;
      if (i >= argc || !end || *end || !(ck_every > 0) || !isfinite(ck_every)) {
        fprintf(stderr, "rhod: --checkpoint-every needs a time in seconds > 0\n%s", USAGE);
        return RHOD_ERR_USAGE;
      }
    } else if (!strncmp(argv[i], "--set=", 6)) {
      if (nsets < 256)
        sets[nsets++] = argv[i] + 6;
    } else if (argv[i][0] == '-') {
      fprintf(stderr, "rhod: unknown option '%s'\n%s", argv[i], USAGE);
      return RHOD_ERR_USAGE;
    } else if (!scene) {
      scene = argv[i];
    } else {
      fprintf(stderr, "rhod: one scene per run ('%s' is extra)\n%s", argv[i], USAGE);
      return RHOD_ERR_USAGE;
    }
  }
  if (!scene) {
    fprintf(stderr, "rhod: run needs a scene file\n%s", USAGE);
    return RHOD_ERR_USAGE;
  }
  run_ctx c;
  memset(&c, 0, sizeof c);
  /* the checkpoint keeps the scene's absolute path, so a resume works from anywhere */
  char scene_abs[4096];
  c.scene_arg = !resume_out && realpath(scene, scene_abs) ? scene_abs : scene;
  c.sets = sets;
  c.nsets = nsets;
  c.ck_every = ck_every;
  int st = rhod_scene_load(scene, sets, nsets, &c.sc, err, sizeof err);
  if (st != RHOD_OK) {
    fprintf(stderr, "rhod: %s\n", err);
    rhod_checkpoint_free(&ck);
    return st;
  }
  char outbuf[4096];
  if (!out) {
    /* default: out/<name of the scene's folder, or the file without .yaml> */
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s", scene);
    char *slash = strrchr(tmp, '/');
    const char *base = slash ? slash + 1 : tmp;
    if (!strcmp(base, "scene.yaml") && slash) {
      *slash = 0;
      char *s2 = strrchr(tmp, '/');
      base = s2 ? s2 + 1 : tmp;
    }
    snprintf(outbuf, sizeof outbuf, "out/%.1000s", base);
    char *dot = strrchr(outbuf, '.');
    if (dot && !strcmp(dot, ".yaml"))
      *dot = 0;
    out = outbuf;
  }
  c.out = out;
  char warn[4096];
  const int nw = rhod_scene_warnings(c.sc, warn, sizeof warn);
  /* set up the particles before touching OUT: a scene that fails here writes nothing */
  st = rhod_sim_init(&c.sim, c.sc, err, sizeof err);
  if (st == RHOD_OK && resume_out) {
    /* the scene must be the one checkpointed, key for key */
    rhod_param_list now_params;
    st = rhod_scene_params(c.sc, &now_params) == RHOD_OK ? RHOD_OK : RHOD_ERR_MEMORY;
    const unsigned nmin = now_params.n < ck.params.n ? now_params.n : ck.params.n;
    unsigned i = 0;
    while (st == RHOD_OK && i < nmin && !strcmp(now_params.keys[i], ck.params.keys[i]) &&
           !strcmp(now_params.values[i], ck.params.values[i]))
      i++;
    if (st == RHOD_OK && (i < nmin || now_params.n != ck.params.n)) {
      snprintf(err, sizeof err,
               "%.400s: the scene changed since the checkpoint in %.400s (key %.100s)", scene,
               resume_out, i < ck.params.n ? ck.params.keys[i] : now_params.keys[i]);
      st = RHOD_ERR_CHECKPOINT;
    }
    rhod_param_list_free(&now_params);
    if (st == RHOD_OK)
      st = rhod_checkpoint_apply(&ck, &c.sim.p, err, sizeof err);
    if (st == RHOD_OK) {
      c.sim.t = ck.t;
      c.sim.step = ck.step;
      c.sim.reflected = ck.reflected;
      c.sim.apr.split_total = ck.splits;
      c.sim.apr.merged_total = ck.merges;
      c.sim.apr.absorbed_total = ck.absorbed;
      c.sim.apr.ke_merged = ck.ke_merged;
      c.sim.apr.ke_absorbed = ck.ke_absorbed;
      c.sim.sph.st_lambda = (real)ck.stiffness;
      c.sim.dt = rhod_sph_dt(&c.sim.sph, &c.sim.p); /* sizes may have been split since t = 0 */
      st = rhod_sim_prepare(&c.sim, 1);
      if (st != RHOD_OK)
        snprintf(err, sizeof err, "out of memory for ghost particles");
    }
  }
  if (st == RHOD_OK)
    st = check_output_dir(out, err, sizeof err);
  if (st != RHOD_OK) {
    fprintf(stderr, "rhod: %s\n", err);
    rhod_sim_free(&c.sim);
    rhod_scene_free(c.sc);
    rhod_checkpoint_free(&ck);
    return st;
  }
  char path[4200];
  snprintf(path, sizeof path, "%s/run.log", out);
  g_log = fopen(path, resume_out ? "a" : "w");
  if (!g_log) {
    fprintf(stderr, "rhod: %s: cannot write: %s\n", path, strerror(errno));
    rhod_sim_free(&c.sim);
    rhod_scene_free(c.sc);
    rhod_checkpoint_free(&ck);
    return RHOD_ERR_OUTPUT;
  }
  rhod_where(c.where, sizeof c.where);
  rhod_sim *s = &c.sim;
  const double t0 = now();
  c.step0 = s->step;
  const int tty = isatty(2);
  if (resume_out)
    logline("rhod: resumed from %s/checkpoint.rhod at t = %.9g s (step %ld)", out, s->t, s->step);
  logline("rhod: scene %s -> %s", c.sc->path, out);
  logline("rhod: kernels run on: %s", c.where);
  if (c.sc->levels > 1)
    logline("rhod: %zu fluid particles, sizes %g m down to %g m (%d levels), R = %g dx, dt = %.4g "
            "s, %s precision",
            s->p.n, c.sc->dx, s->dx_min, c.sc->levels, c.sc->radius_ratio, s->dt, RHOD_REAL_NAME);
  else
    logline("rhod: %zu fluid particles, dx = %g m, R = %g m, dt = %.4g s, %s precision", s->p.n,
            c.sc->dx, c.sc->dx * c.sc->radius_ratio, s->dt, RHOD_REAL_NAME);
  if (nw > 0) {
    char *line = strtok(warn, "\n");
    while (line) {
      logline("rhod: warning: %s", line);
      line = strtok(NULL, "\n");
    }
  }
  rhod_scene_params(c.sc, &c.params);
  c.nprobe_cols = rhod_probe_columns(c.sc, c.probe_buf, c.probe_names, RHOD_PROBE_COLUMNS_TOTAL);
  c.probe_vals = calloc(c.nprobe_cols + 1, sizeof(double));
  snprintf(path, sizeof path, "%s/probes.csv", out);
  if (resume_out)
    st = rhod_csv_reopen(&c.csv, path, c.nprobe_cols, ck.probes_bytes, err, sizeof err);
  else
    st = rhod_csv_open(&c.csv, path, c.nprobe_cols, c.probe_names, err, sizeof err);
  if (st != RHOD_OK)
    goto fail;
  c.csv_open = 1;

  const double t_end = c.sc->t_end, dout = c.sc->output_every, dprobe = c.sc->probe_every;
  double next_out = 0, next_probe = 0;
  c.next_ck = ck_every;
  if (resume_out) {
    next_out = ck.next_out, next_probe = ck.next_probe, c.next_ck = ck.next_checkpoint;
    c.snap_cap = ck.nsnap + 16;
    c.snap_t = malloc(sizeof(double) * (size_t)c.snap_cap);
    c.snap_n = malloc(sizeof(size_t) * (size_t)c.snap_cap);
    if (!c.snap_t || !c.snap_n) {
      st = RHOD_ERR_MEMORY;
      snprintf(err, sizeof err, "out of memory");
      goto fail;
    }
    for (int i = 0; i < ck.nsnap; i++)
      c.snap_t[i] = ck.snap_t[i], c.snap_n[i] = (size_t)ck.snap_n[i];
    c.nsnap = ck.nsnap;
  }
  g_stop = 0;
  signal(SIGINT, on_signal);
  signal(SIGTERM, on_signal);
  double last_progress = -1;
  int last_decile = -1;
  const double eps = 1e-9 * t_end;
  for (;;) {
    const int done = s->t >= t_end - eps;
    if (s->t >= next_probe - eps || done) {
      rhod_probe_values(s, c.probe_vals);
      st = rhod_csv_row(&c.csv, s->t, c.probe_vals, err, sizeof err);
      if (st != RHOD_OK)
        goto fail;
      while (next_probe <= s->t + eps)
        next_probe += dprobe;
    }
    if (s->t >= next_out - eps || done) {
      st = write_output(&c, err, sizeof err);
      if (st != RHOD_OK)
        goto fail;
      logline("rhod: t = %.6g s: snapshot %d (%zu particles)", s->t, c.nsnap - 1, s->p.n);
      while (next_out <= s->t + eps)
        next_out += dout;
    }
    if (done)
      break;
    if ((c.ck_every > 0 && s->t >= c.next_ck - eps) || g_stop) {
      while (c.ck_every > 0 && c.next_ck <= s->t + eps)
        c.next_ck += c.ck_every;
      st = write_checkpoint(&c, next_out, next_probe, err, sizeof err);
      if (st != RHOD_OK)
        goto fail;
      if (g_stop) {
        logline("rhod: %s at t = %.9g s: checkpoint written; continue with: rhod resume %s",
                g_stop == SIGINT ? "interrupted" : "terminated", s->t, out);
        write_summary(&c, "interrupted", "signal", now() - t0);
        st = RHOD_ERR_INTERRUPTED;
        goto cleanup;
      }
    }
    st = rhod_sim_dt(s);
    if (st != RHOD_OK) {
      snprintf(err, sizeof err, "out of memory for ghost particles at t = %g s", s->t);
      goto fail;
    }
    double dt = s->dt;
    /* land exactly on output times and on the end */
    const double stop = fmin(t_end, next_out);
    if (s->t + dt > stop - eps)
      dt = stop - s->t;
    else if (s->t + 2 * dt > stop)
      dt = 0.5 * (stop - s->t);
    st = rhod_sim_step(s, dt, err, sizeof err);
    if (st != RHOD_OK)
      goto fail;
    st = rhod_sim_prepare(s, 1);
    if (st != RHOD_OK) {
      snprintf(err, sizeof err, "out of memory for ghost particles at t = %g s", s->t);
      goto fail;
    }
    const double w = now() - t0;
    const double frac = s->t / t_end;
    if ((tty && w - last_progress > 0.25) || (!tty && (int)(frac * 10) > last_decile)) {
      last_progress = w;
      last_decile = (int)(frac * 10);
      char eta[32];
      fmt_hms(frac > 0 ? w * (1 - frac) / frac : 0, eta, sizeof eta);
      fprintf(stderr,
              "%st = %.5g s  %5.1f%%  N = %zu  dt = %.3g s  %.3g particle-steps/s  ETA %s%s",
              tty ? "\r" : "", s->t, 100 * frac, s->p.n, s->dt, s->particle_steps / (w > 0 ? w : 1),
              eta, tty ? "   " : "\n");
      fflush(stderr);
    }
  }
  if (tty)
    fprintf(stderr, "\n");
  {
    const double wall = now() - t0;
    const double psteps = s->particle_steps;
    logline("rhod: done: %ld steps, %.3f s wall, %.4g us per particle-step", s->step, wall,
            psteps > 0 ? 1e6 * wall / psteps : 0.0);
    if (s->apr.split_total || s->apr.merged_total)
      logline("rhod: %ld particles split by the refinement criteria and %ld groups of %d "
              "coalesced during the run (%zu particles now)",
              s->apr.split_total, s->apr.merged_total, s->apr.nsplit, s->p.n);
    if (s->apr.merged_total || s->apr.absorbed_total)
      logline("rhod: %ld stragglers absorbed by their coarser neighbours; the merges took "
              "%.4g J/m of kinetic energy out, the absorptions %.4g J/m",
              s->apr.absorbed_total, s->apr.ke_merged, s->apr.ke_absorbed);
    if (s->reflected)
      logline("rhod: %ld particle-steps ended just behind a wall and were reflected back "
              "(docs/choices.md)",
              s->reflected);
    if (s->damper_limited)
      logline("rhod: %ld of the %ld steps run here took a dt set by the acoustic damper's "
              "measured stiffness (scheme.damper_step_limit)",
              s->damper_limited, s->step - c.step0);
    if (s->stiffness_limited)
      logline("rhod: %ld of the %ld steps run here took a dt set by the stiffness the RK4 "
              "stages measured (time.stiffness_limit)",
              s->stiffness_limited, s->step - c.step0);
    st = write_summary(&c, "ok", "", wall);
  }
  goto cleanup;
fail:
  if (tty)
    fprintf(stderr, "\n");
  fprintf(stderr, "rhod: %s\n", err);
  if (g_log) {
    fprintf(g_log, "rhod: error: %s\n", err);
    fflush(g_log);
  }
  {
    char cause[ERRLEN];
    size_t k = 0;
    for (const char *q = err; *q && k < sizeof cause - 2; q++)
      if (*q != '"' && *q != '\\')
        cause[k++] = *q;
    cause[k] = 0;
    write_summary(&c, st == RHOD_ERR_UNSTABLE ? "unstable" : "error", cause, now() - t0);
    if (st == RHOD_ERR_UNSTABLE)
      fprintf(stderr, "rhod: the last good snapshot is %s/snapshot_%04d.h5 (t = %g s)\n", out,
              c.nsnap - 1, c.nsnap ? c.snap_t[c.nsnap - 1] : 0.0);
  }
cleanup:
  signal(SIGINT, SIG_DFL);
  signal(SIGTERM, SIG_DFL);
  rhod_checkpoint_free(&ck);
  if (c.csv_open) {
    char e2[ERRLEN];
    if (rhod_csv_close(&c.csv, e2, sizeof e2) != RHOD_OK && st == RHOD_OK) {
      fprintf(stderr, "rhod: %s\n", e2);
      st = RHOD_ERR_IO;
    }
  }
  if (g_log)
    fclose(g_log);
  g_log = NULL;
  rhod_param_list_free(&c.params);
  free(c.snap_t);
  free(c.snap_n);
  free(c.probe_vals);
  rhod_sim_free(&c.sim);
  rhod_scene_free(c.sc);
  return st;
}

int main(int argc, char **argv) {
  if (argc < 2 || !strcmp(argv[1], "--help") || !strcmp(argv[1], "-h")) {
    fputs(USAGE, argc < 2 ? stderr : stdout);
    return argc < 2 ? RHOD_ERR_USAGE : 0;
  }
  if (!strcmp(argv[1], "--version")) {
    printf("rhod 0.1 (%s precision, %s)\n", RHOD_REAL_NAME,
#ifdef RHOD_OFFLOAD
           "nvptx offload"
#else
           "host OpenMP"
#endif
    );
    return 0;
  }
  if (!strcmp(argv[1], "run"))
    return cmd_run(argc - 2, argv + 2, NULL);
  if (!strcmp(argv[1], "resume")) {
    if (argc != 3) {
      fprintf(stderr, "rhod: resume needs exactly one output folder\n%s", USAGE);
      return RHOD_ERR_USAGE;
    }
    return cmd_run(0, NULL, argv[2]);
  }
  fprintf(stderr, "rhod: unknown command '%s'\n%s", argv[1], USAGE);
  return RHOD_ERR_USAGE;
}
