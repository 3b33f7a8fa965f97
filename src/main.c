/* rhod: command line. The only place that prints to the terminal and exits. */
#define _GNU_SOURCE /* getopt_long, flock, realpath */
#include "rhod/checkpoint.h"
#include "rhod/io.h"
#include "rhod/rhodsph/scene.h"
#include "rhod/scene.h"
#include "rhod/schedule.h"
#include "rhod/sim.h"
#include "rhod/version.h"
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <float.h>
#include <getopt.h>
#include <jansson.h>
#include <math.h>
#include <omp.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define ERRLEN 1024
#define MAX_SETS 256

static const char *USAGE =
    "usage: rhod run SCENE [-o OUT] [--set dotted.key=value]... [--checkpoint-every T]\n"
    "                [--overwrite]\n"
    "       rhod resume OUT\n"
    "       rhod check SCENE [--set dotted.key=value]...\n"
    "       rhod help [run | resume | check] | --help | --version\n";

static const char *HELP_RUN =
    "usage: rhod run SCENE [options]\n"
    "Runs the scene and writes snapshots (HDF5 + XDMF), pictures (PNG), probes.csv,\n"
    "summary.json, run.log, scene.yaml (the scene as run) and the walls (walls.h5,\n"
    "walls.xdmf) into the output folder.\n"
    "  -o, --output=DIR          output folder (default out/NAME, NAME the scene file's name\n"
    "                            without .yaml, or its folder's name for a scene.yaml)\n"
    "      --set=KEY=VALUE       overrides a key of the scene (dotted path, e.g.\n"
    "                            particles.dx=0.01 or fluid.0.velocity=[1,0]); repeatable\n"
    "      --checkpoint-every=T  writes OUT/checkpoint.rhod every T simulated seconds\n"
    "      --overwrite           the output folder may hold an earlier run: its run files\n"
    "                            are removed first (other files are kept)\n"
    "  -h, --help                this text\n"
    "A folder that is not empty is refused without --overwrite; one run writes into a\n"
    "folder at a time. SIGINT or SIGTERM writes a checkpoint and stops (exit 9).\n"
    "Exit codes: 0 ok, 2 usage, 3 unreadable scene, 4 invalid scene, 5 output folder,\n"
    "6 unstable run, 7 write error during the run, 8 out of memory, 9 interrupted\n"
    "(checkpoint written), 10 bad or unfitting checkpoint.\n";

static const char *HELP_RESUME =
    "usage: rhod resume OUT\n"
    "Continues the run in OUT from OUT/checkpoint.rhod, bit for bit. The scene file and its\n"
    "--set overrides are those of the checkpoint; a scene that changed since, or output\n"
    "files that do not belong to the checkpoint's run, are refused (exit 10).\n"
    "  -h, --help   this text\n";

static const char *HELP_CHECK =
    "usage: rhod check SCENE [--set=KEY=VALUE]...\n"
    "Loads and validates the scene, builds the initial particles and prints their count,\n"
    "the memory they need, the first time step, an estimate of the number of steps and\n"
    "one line per body (its motion and resolved centre, mass, inertia) and per open boundary\n"
    "(its kind, length, resolved normal and inflow velocity). Writes nothing.\n"
    "  -h, --help   this text\n";

/* ---- terminal output ------------------------------------------------------------------ */

/* SIGINT/SIGTERM: the loop stops after the step in progress, writes a checkpoint and
 * exits with RHOD_ERR_INTERRUPTED. The handler stays installed (sigaction without
 * SA_RESETHAND), so a second signal only sets the flag again. */
static volatile sig_atomic_t g_stop;
static void on_signal(int sig) { g_stop = sig; }

static FILE *g_log;
static int g_progress_shown; /* a live progress line (no newline) is on the terminal */

/* A message as one line: control characters (a newline in a key or path) are escaped. */
static void one_line(const char *in, char *out, size_t len) {
  size_t k = 0;
  for (const unsigned char *q = (const unsigned char *)in; *q && k + 5 < len; q++) {
    if (*q == '\n')
      out[k++] = '\\', out[k++] = 'n';
    else if (*q == '\t')
      out[k++] = '\\', out[k++] = 't';
    else if (*q < 0x20 || *q == 0x7f)
      k += (size_t)snprintf(out + k, len - k, "\\x%02x", *q);
    else
      out[k++] = (char)*q;
  }
  out[k] = 0;
}

static void clear_progress(void) {
  if (g_progress_shown) {
    fputs("\r\033[K", stderr);
    g_progress_shown = 0;
  }
}

/* One line, control characters escaped, after clearing a live progress line. */
static void emit(FILE *to, const char *prefix, int to_log, const char *fmt, va_list ap) {
  char buf[4096], line[8192];
  vsnprintf(buf, sizeof buf, fmt, ap);
  one_line(buf, line, sizeof line);
  clear_progress();
  fprintf(to, "%s%s\n", prefix, line);
  fflush(to);
  if (to_log && g_log) {
    fprintf(g_log, "%s\n", line);
    fflush(g_log);
  }
}

/* A line on stdout and into run.log. */
static void logline(const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  emit(stdout, "", 1, fmt, ap);
  va_end(ap);
}

/* "rhod: message" on stderr. */
static void report(const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  emit(stderr, "rhod: ", 0, fmt, ap);
  va_end(ap);
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static void fmt_hms(double s, char *buf, size_t len) {
  if (!isfinite(s) || s < 0)
    s = 0;
  if (s > 1e9)
    s = 1e9;
  long t = (long)(s + 0.5);
  snprintf(buf, len, "%02ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
}

/* ---- the output folder ---------------------------------------------------------------- */

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

/* The default output folder: out/NAME, NAME the scene file's name without .yaml (.yml),
 * or the name of its folder for a file called scene.yaml. Never "." or "..": the name is
 * taken from the resolved path, and a name that is still not a plain one becomes
 * "scene". */
static void default_out(const char *scene, char *buf, size_t len) {
  char tmp[4096];
  char *abs = realpath(scene, NULL);
  snprintf(tmp, sizeof tmp, "%s", abs ? abs : scene);
  free(abs);
  size_t l = strlen(tmp);
  while (l > 1 && tmp[l - 1] == '/')
    tmp[--l] = 0;
  char *slash = strrchr(tmp, '/');
  char *base = slash ? slash + 1 : tmp;
  if ((!strcmp(base, "scene.yaml") || !strcmp(base, "scene.yml")) && slash && slash > tmp) {
    *slash = 0;
    char *s2 = strrchr(tmp, '/');
    base = s2 ? s2 + 1 : tmp;
  } else {
    char *dot = strrchr(base, '.');
    if (dot && dot != base && (!strcmp(dot, ".yaml") || !strcmp(dot, ".yml")))
      *dot = 0;
  }
  if (!base[0] || base[0] == '.' || strchr(base, '/'))
    base = "scene";
  snprintf(buf, len, "out/%.1000s", base);
}

/* The files a run writes into its folder (what --overwrite removes): the snapshots and
 * their pictures, the XDMF and walls files, probes.csv, summary.json, run.log,
 * scene.yaml, checkpoint.rhod, and the .tmp names they are written under. */
static int is_run_file(const char *name) {
  static const char *const fixed[] = {"snapshots.xdmf", "walls.h5",        "walls.xdmf",
                                      "probes.csv",     "summary.json",    "run.log",
                                      "scene.yaml",     "checkpoint.rhod", ".rhod_write_test"};
  char n[512];
  snprintf(n, sizeof n, "%s", name);
  size_t l = strlen(n);
  if (l > 4 && !strcmp(n + l - 4, ".tmp"))
    n[l -= 4] = 0;
  for (size_t k = 0; k < sizeof fixed / sizeof fixed[0]; k++)
    if (!strcmp(n, fixed[k]))
      return 1;
  if (strncmp(n, "snapshot_", 9) != 0)
    return 0;
  size_t d = 9;
  while (n[d] >= '0' && n[d] <= '9')
    d++;
  return d >= 13 && (!strcmp(n + d, ".h5") || !strcmp(n + d, ".png"));
}

#define LOCK_NAME ".rhod.lock"

/* Creates OUT, takes its lock (flock on OUT/.rhod.lock, held until the process ends:
 * a second run into the same folder refuses, naming the first), checks that it can be
 * written and, for a new run, that it holds no earlier run: without `overwrite` a folder
 * with any file is refused; with it, the run files of the earlier run are removed. */
static int prepare_output(const char *out, int resume, int overwrite, int *lockfd, char *err,
                          size_t len) {
  *lockfd = -1;
  if (mkdir_p(out) != 0) {
    snprintf(err, len, "%.900s: cannot create output folder: %s", out, strerror(errno));
    return RHOD_ERR_OUTPUT;
  }
  char path[4200];
  snprintf(path, sizeof path, "%s/" LOCK_NAME, out);
  int fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) {
    snprintf(err, len, "%.900s: output folder is not writable: %s", out, strerror(errno));
    return RHOD_ERR_OUTPUT;
  }
  if (flock(fd, LOCK_EX | LOCK_NB) != 0) {
    char pid[32] = "";
    ssize_t got = pread(fd, pid, sizeof pid - 1, 0);
    pid[got > 0 ? got : 0] = 0;
    pid[strcspn(pid, "\n")] = 0;
    snprintf(err, len,
             "%.900s: another rhod run (pid %s) is writing into this folder; wait for it or "
             "choose another folder with -o",
             out, pid[0] ? pid : "unknown");
    close(fd);
    return RHOD_ERR_OUTPUT;
  }
  char pid[32];
  const int pl = snprintf(pid, sizeof pid, "%ld\n", (long)getpid());
  if (ftruncate(fd, 0) != 0 || pwrite(fd, pid, (size_t)pl, 0) != pl) {
    snprintf(err, len, "%.900s: output folder is not writable: %s", out, strerror(errno));
    close(fd);
    return RHOD_ERR_OUTPUT;
  }
  *lockfd = fd;
  snprintf(path, sizeof path, "%s/.rhod_write_test", out);
  FILE *f = fopen(path, "w");
  if (!f || fputs("x", f) < 0 || fclose(f) != 0) {
    snprintf(err, len, "%.900s: output folder is not writable: %s", out, strerror(errno));
    return RHOD_ERR_OUTPUT;
  }
  remove(path);
  if (resume)
    return RHOD_OK;
  DIR *d = opendir(out);
  if (!d) {
    snprintf(err, len, "%.900s: cannot list the output folder: %s", out, strerror(errno));
    return RHOD_ERR_OUTPUT;
  }
  int others = 0, removed_fail = 0;
  char first[256] = "";
  struct dirent *e;
  while ((e = readdir(d))) {
    if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..") || !strcmp(e->d_name, LOCK_NAME))
      continue;
    if (!overwrite) {
      if (!others++)
        snprintf(first, sizeof first, "%.200s", e->d_name);
      continue;
    }
    if (!is_run_file(e->d_name))
      continue;
    snprintf(path, sizeof path, "%s/%s", out, e->d_name);
    if (unlink(path) != 0 && !removed_fail++)
      snprintf(first, sizeof first, "%.200s: %.40s", e->d_name, strerror(errno));
  }
  closedir(d);
  if (others) {
    snprintf(err, len,
             "%.700s: output folder is not empty (it holds %s%s): give --overwrite to replace "
             "an earlier run's files, or choose another folder with -o",
             out, first, others > 1 ? " and more" : "");
    return RHOD_ERR_OUTPUT;
  }
  if (removed_fail) {
    snprintf(err, len, "%.900s: --overwrite cannot remove %s", out, first);
    return RHOD_ERR_OUTPUT;
  }
  return RHOD_OK;
}

/* A resume appends to the output of the checkpoint's run: every snapshot the checkpoint
 * lists must be that run's (its time and particle count; a missing one is only reported)
 * and probes.csv at least as long as at the checkpoint. Nothing is written here. */
static int check_resume_files(const char *out, const rhod_checkpoint *ck, int *missing, char *err,
                              size_t len) {
  char path[4200];
  *missing = 0;
  snprintf(path, sizeof path, "%s/probes.csv", out);
  const int st = rhod_csv_check(path, ck->probes_bytes, err, len);
  if (st != RHOD_OK)
    return st;
  for (int i = 0; i < ck->nsnap; i++) {
    snprintf(path, sizeof path, "%s/snapshot_%04d.h5", out, i);
    if (access(path, F_OK) != 0) {
      (*missing)++;
      continue;
    }
    double t = 0;
    uint64_t n = 0;
    char e2[ERRLEN];
    if (rhod_read_snapshot_header(path, &t, &n, e2, sizeof e2) != RHOD_OK) {
      snprintf(err, len, "%.900s (resume)", e2);
      return RHOD_ERR_CHECKPOINT;
    }
    if (t != ck->snap_t[i] || n != ck->snap_n[i]) {
      snprintf(err, len,
               "%.700s: t = %.9g s with %llu particles, but the checkpoint's run wrote t = %.9g "
               "s with %llu: the folder holds another run's files",
               path, t, (unsigned long long)n, ck->snap_t[i], (unsigned long long)ck->snap_n[i]);
      return RHOD_ERR_CHECKPOINT;
    }
  }
  return RHOD_OK;
}

/* ---- the run -------------------------------------------------------------------------- */

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
  const char *probe_names[RHOD_RUN_COLUMNS_MAX];
  char probe_buf[RHOD_RUN_COLUMNS_MAX][RHOD_PROBE_NAME_MAX];
  char where[256];
  /* checkpoints */
  const char *scene_arg;
  const char **sets;
  int nsets;
  double ck_every, next_ck;
  long step0;          /* steps done before this process (a resume) */
  double pic_range[2]; /* the pictures' colour range: given, or fixed at the first
                          picture whose field has one (NaN, NaN before) */
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
  if (c->sim.ops->save)
    c->sim.ops->save(&c->sim, &ck);      /* the scheme's scalars */
  rhod_bodies_save(&c->sim.bodies, &ck); /* and the bodies' motion */
  rhod_open_save(&c->sim.open, &ck);     /* and the open boundaries' bookkeeping */
  ck.picture_range[0] = c->pic_range[0];
  ck.picture_range[1] = c->pic_range[1];
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
  int st = rhod_sim_fetch(s, &v);
  if (st != RHOD_OK) {
    snprintf(err, len, "out of memory for ghost particles");
    return st;
  }
  st = rhod_snapshot_check(&v, err, len);
  if (st != RHOD_OK)
    return st;
  st = rhod_write_snapshot(c->out, c->nsnap, &v, &c->params, err, len);
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
  /* the bodies' outlines keep their point counts through a run: this snapshot's serve
   * for the earlier ones (a resume included) */
  st = rhod_write_xdmf_bodies(c->out, c->nsnap, c->snap_t, c->snap_n, rhod_snapshot_fields(&v),
                              v.extra, v.nextra, v.n_bodies ? v.body_start[v.n_bodies] : 0, err,
                              len);
  if (st != RHOD_OK)
    return st;
  const rhod_scene *sc = c->sc;
  if (!sc->picture_enabled) /* output.picture: false */
    return RHOD_OK;
  char png[4200];
  snprintf(png, sizeof png, "%s/snapshot_%04d.png", c->out, c->nsnap - 1);
  const double *lo = sc->picture_box_set ? sc->picture_box_min : s->lo;
  const double *hi = sc->picture_box_set ? sc->picture_box_max : s->hi;
  /* one colour range for the whole run: the scene's, else the first picture's whose
   * field spans one (a fluid at rest has no velocity range yet) */
  if (isnan(c->pic_range[0])) {
    double r[2];
    if (rhod_picture_field_range(&v, sc->picture_field, r) == 0 && r[0] < r[1])
      c->pic_range[0] = r[0], c->pic_range[1] = r[1];
  }
  st = rhod_write_picture(png, &v, sc->picture_field, sc->picture_size_panel, sc->picture_width, lo,
                          hi, isnan(c->pic_range[0]) ? NULL : c->pic_range, sc->walls, sc->n_walls,
                          err, len);
  return st;
}

/* A number for JSON: null when not finite (JSON has no inf or NaN). */
static json_t *jnum(double v) { return isfinite(v) ? json_real(v) : json_null(); }

/* A string for JSON: as it is when it is UTF-8, else with each byte above 0x7f as '?'. */
static json_t *jstr(const char *v) {
  json_t *j = json_string(v ? v : "");
  if (j)
    return j;
  char *a = strdup(v);
  for (char *q = a; q && *q; q++)
    if ((unsigned char)*q > 0x7f)
      *q = '?';
  j = json_string(a ? a : "");
  free(a);
  return j;
}

static int write_summary(run_ctx *c, const char *status, const char *cause, double wall) {
  rhod_sim *s = &c->sim;
  const double psteps = s->particle_steps;
  json_t *probes = json_object();
  for (unsigned k = 0; probes && k < c->nprobe_cols; k++)
    json_object_set_new(probes, c->probe_names[k], jnum(c->probe_vals ? c->probe_vals[k] : 0.0));
  json_t *o = json_object();
  if (o) {
    json_object_set_new(o, "status", jstr(status));
    json_object_set_new(o, "rhod_version", jstr(rhod_version()));
    json_object_set_new(o, "git_commit", jstr(rhod_commit()));
    json_object_set_new(o, "cause", jstr(cause));
    json_object_set_new(o, "scene", jstr(c->sc->path));
    json_object_set_new(o, "particles", json_integer((json_int_t)s->p.n));
    json_object_set_new(o, "steps", json_integer(s->step));
    json_object_set_new(o, "time", jnum(s->t));
    json_object_set_new(o, "dt", jnum(s->dt));
    json_object_set_new(o, "wall_seconds", jnum(wall));
    json_object_set_new(o, "us_per_particle_step", jnum(psteps > 0 ? 1e6 * wall / psteps : 0.0));
    json_object_set_new(o, "precision", json_string(RHOD_REAL_NAME));
    json_object_set_new(o, "threads", json_integer(omp_get_max_threads()));
    json_object_set_new(o, "kernels_ran_on", jstr(c->where));
    json_object_set_new(o, "scheme", jstr(s->ops ? s->ops->name : ""));
    json_object_set_new(o, "wall_reflections", json_integer(s->reflected));
    if (s->open.n > 0) { /* the open boundaries' mass balance (open.h), kg per unit depth */
      const rhod_open *ob = &s->open;
      json_object_set_new(o, "open_mass_in", jnum(ob->taken_in));
      json_object_set_new(o, "open_mass_out", jnum(ob->taken_out));
      json_object_set_new(o, "open_prescribed_in", jnum(ob->prescribed_in));
      json_object_set_new(o, "open_prescribed_out", jnum(ob->prescribed_out));
      json_object_set_new(o, "open_fluid_mass_start", jnum(ob->mass0));
      const double mass = rhod_open_mass(&s->p);
      json_object_set_new(o, "open_fluid_mass", jnum(mass));
      /* the fluid's change less (in - out): round-off (the figures above have 9 digits) */
      json_object_set_new(o, "open_balance_error",
                          jnum(mass - ob->mass0 - (ob->taken_in - ob->taken_out)));
      json_object_set_new(o, "open_particles_made", json_integer((json_int_t)ob->created));
      json_object_set_new(o, "open_particles_removed", json_integer((json_int_t)ob->deleted));
    }
    rhod_stat stats[RHOD_MAX_STATS];
    const int ns = rhod_sim_stats(s, stats, RHOD_MAX_STATS);
    for (int k = 0; k < ns; k++)
      json_object_set_new(o, stats[k].key,
                          stats[k].integer ? json_integer((json_int_t)stats[k].value)
                                           : jnum(stats[k].value));
    json_object_set_new(o, "probes", probes ? probes : json_null());
  }
  char *text =
      o ? json_dumps(o, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(9)) : NULL;
  json_decref(o);
  char path[4200], err[ERRLEN];
  snprintf(path, sizeof path, "%s/summary.json", c->out);
  int st;
  if (!text) {
    snprintf(err, sizeof err, "%.900s: cannot write: out of memory (or text that is not UTF-8)",
             path);
    st = RHOD_ERR_MEMORY;
  } else {
    const size_t l = strlen(text);
    char *nl = realloc(text, l + 2);
    if (nl)
      text = nl, text[l] = '\n', text[l + 1] = 0;
    st = rhod_write_file_atomic(path, text, err, sizeof err);
    free(text);
  }
  if (st != RHOD_OK)
    report("%s", err);
  return st;
}

typedef struct {
  const char *scene;
  const char *out;
  const char *sets[MAX_SETS];
  int nsets;
  double ck_every;
  int overwrite;
} run_opts;

static void install_signals(void) {
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART; /* no SA_RESETHAND: a second signal is caught too */
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);
}

static int run(run_opts *o, const char *resume_out) {
  rhod_checkpoint ck;
  memset(&ck, 0, sizeof ck);
  char err[ERRLEN] = "";
  int lockfd = -1;
  if (resume_out) {
    char path[4200];
    snprintf(path, sizeof path, "%s/checkpoint.rhod", resume_out);
    int st = rhod_checkpoint_read(path, &ck, err, sizeof err);
    if (st == RHOD_OK && (ck.nsets < 0 || ck.nsets > MAX_SETS)) {
      snprintf(err, sizeof err, "%.900s: %d overrides, more than the %d a run takes", path,
               (int)ck.nsets, MAX_SETS);
      st = RHOD_ERR_CHECKPOINT;
    }
    if (st != RHOD_OK) {
      report("%s", err);
      rhod_checkpoint_free(&ck);
      return st;
    }
    o->scene = ck.scene_path;
    o->out = resume_out;
    o->nsets = ck.nsets;
    for (int i = 0; i < o->nsets; i++)
      o->sets[i] = ck.sets[i];
    o->ck_every = ck.checkpoint_every;
  }
  const char *scene = o->scene;
  run_ctx c;
  memset(&c, 0, sizeof c);
  /* the checkpoint keeps the scene's absolute path, so a resume works from anywhere */
  char scene_abs[4096];
  c.scene_arg = !resume_out && realpath(scene, scene_abs) ? scene_abs : scene;
  c.sets = o->sets;
  c.nsets = o->nsets;
  c.ck_every = o->ck_every;
  int st = rhod_scene_load(scene, o->sets, o->nsets, &c.sc, err, sizeof err);
  /* a checkpoint interval the run could not keep (more checkpoints than snapshots allowed) */
  if (st == RHOD_OK && o->ck_every > 0 && !(c.sc->t_end / o->ck_every <= RHOD_MAX_SNAPSHOTS)) {
    snprintf(err, sizeof err,
             "--checkpoint-every %g s: %.3g checkpoints to time.end = %g s, more than %g; give a "
             "longer interval",
             o->ck_every, c.sc->t_end / o->ck_every, c.sc->t_end, RHOD_MAX_SNAPSHOTS);
    st = resume_out ? RHOD_ERR_CHECKPOINT : RHOD_ERR_USAGE;
    rhod_scene_free(c.sc);
  }
  if (st != RHOD_OK) {
    report("%s", err);
    rhod_checkpoint_free(&ck);
    return st;
  }
  c.pic_range[0] = c.pic_range[1] = NAN;
  if (c.sc->picture_range_set)
    c.pic_range[0] = c.sc->picture_range[0], c.pic_range[1] = c.sc->picture_range[1];
  else if (resume_out)
    c.pic_range[0] = ck.picture_range[0], c.pic_range[1] = ck.picture_range[1];
  char outbuf[4096];
  if (!o->out) {
    default_out(scene, outbuf, sizeof outbuf);
    o->out = outbuf;
  }
  const char *out = o->out;
  c.out = out;
  char warn[4096];
  const int nw = rhod_scene_warnings(c.sc, warn, sizeof warn);
  /* set up the particles before touching OUT: a scene that fails here writes nothing */
  st = rhod_sim_init(&c.sim, c.sc, err, sizeof err);
  char simwarn[4096] = "";
  /* the particles as set up at t = 0 (a resume carries on from a later state: none) */
  const int nsw =
      st == RHOD_OK && !resume_out ? rhod_sim_warnings(&c.sim, simwarn, sizeof simwarn) : 0;
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
      /* the scheme's scalars (and its dt: sizes may have been split since t = 0) */
      if (c.sim.ops->load)
        st = c.sim.ops->load(&c.sim, &ck, err, sizeof err);
      if (st == RHOD_OK) {
        st = rhod_bodies_load(&c.sim.bodies, &c.sim.bnd, &ck, err, sizeof err);
        if (st == RHOD_OK)
          st = rhod_open_load(&c.sim.open, &ck, err, sizeof err);
        if (st != RHOD_OK) { /* "OUT/checkpoint.rhod: reason" */
          char why[512];
          snprintf(why, sizeof why, "%s", err);
          snprintf(err, sizeof err, "%s/checkpoint.rhod: %s", resume_out, why);
        }
      }
    }
    if (st == RHOD_OK) {
      st = rhod_sim_prepare(&c.sim, 1);
      if (st != RHOD_OK)
        snprintf(err, sizeof err, "out of memory for ghost particles");
    }
  }
  /* the state that will be written first, checked before anything is written */
  if (st == RHOD_OK) {
    rhod_snapshot_view v;
    rhod_sim_fetch(&c.sim, &v);
    st = rhod_snapshot_check(&v, err, sizeof err);
    if (st == RHOD_OK && !(isfinite(c.sim.dt) && c.sim.dt > 0)) {
      snprintf(err, sizeof err,
               "unstable at t = %.6g s: the time step is %g s, not finite and positive (check "
               "the speed of sound, densities and gravity); nothing was written",
               c.sim.t, c.sim.dt);
      st = RHOD_ERR_UNSTABLE;
    }
  }
  int missing = 0;
  /* a resume's files checked first: a refused resume leaves the folder as it was */
  if (st == RHOD_OK && resume_out)
    st = check_resume_files(out, &ck, &missing, err, sizeof err);
  if (st == RHOD_OK)
    st = prepare_output(out, resume_out != NULL, o->overwrite, &lockfd, err, sizeof err);
  if (st == RHOD_OK)
    st = rhod_write_walls(out, c.sc, err, sizeof err);
  if (st != RHOD_OK) {
    report("%s", err);
    rhod_sim_free(&c.sim);
    rhod_scene_free(c.sc);
    rhod_checkpoint_free(&ck);
    if (lockfd >= 0)
      close(lockfd);
    return st;
  }
  /* from the first file written on, SIGINT and SIGTERM end with a checkpoint */
  g_stop = 0;
  install_signals();
  rhod_scene_params(c.sc, &c.params);
  c.nprobe_cols = rhod_probe_columns(c.sc, c.probe_buf, c.probe_names, RHOD_RUN_COLUMNS_MAX);
  c.probe_vals = calloc(c.nprobe_cols + 1, sizeof(double));
  char path[4200];
  snprintf(path, sizeof path, "%s/probes.csv", out);
  /* probes.csv first: a resume whose probes do not fit stops before run.log grows */
  if (resume_out)
    st = rhod_csv_reopen(&c.csv, path, c.nprobe_cols, ck.probes_bytes, err, sizeof err);
  else
    st = rhod_csv_open(&c.csv, path, c.nprobe_cols, c.probe_names, err, sizeof err);
  if (st != RHOD_OK) {
    report("%s", err);
    free(c.probe_vals);
    rhod_param_list_free(&c.params);
    rhod_sim_free(&c.sim);
    rhod_scene_free(c.sc);
    rhod_checkpoint_free(&ck);
    close(lockfd);
    return st;
  }
  c.csv_open = 1;
  const double t0 = now();
  snprintf(path, sizeof path, "%s/run.log", out);
  g_log = fopen(path, resume_out ? "a" : "w");
  if (!g_log) {
    snprintf(err, sizeof err, "%.900s: cannot write: %s", path, strerror(errno));
    st = RHOD_ERR_OUTPUT;
    goto fail;
  }
  if (!resume_out) {
    /* the scene as run: `rhod run OUT/scene.yaml` repeats the run */
    snprintf(path, sizeof path, "%s/scene.yaml", out);
    char head[8192];
    snprintf(head, sizeof head,
             "# The scene as run by rhod: %s with every default filled in%s.\n# rhod run "
             "OUT/scene.yaml repeats the run.\n",
             c.sc->path, o->nsets ? " and its --set overrides applied" : "");
    char *text = malloc(strlen(head) + strlen(c.sc->yaml) + 1);
    if (!text) {
      st = RHOD_ERR_MEMORY;
      snprintf(err, sizeof err, "out of memory");
      goto fail;
    }
    strcpy(text, head);
    strcat(text, c.sc->yaml);
    st = rhod_write_file_atomic(path, text, err, sizeof err);
    free(text);
    if (st != RHOD_OK)
      goto fail;
  }
  rhod_where(c.where, sizeof c.where);
  rhod_sim *s = &c.sim;
  c.step0 = s->step;
  const int tty = isatty(2);
  if (resume_out)
    logline("rhod: resumed from %s/checkpoint.rhod at t = %.9g s (step %ld)", out, s->t, s->step);
  logline("rhod: scene %s -> %s", c.sc->path, out);
  logline("rhod: kernels run on: %s", c.where);
  const int levels = c.sc->rs ? c.sc->rs->levels : 1; /* refinement.levels (rhodsph) */
  if (levels > 1)
    logline("rhod: %zu fluid particles, sizes %g m down to %g m (%d levels), R = %g dx, dt = %.4g "
            "s, %s precision",
            s->p.n, c.sc->dx, s->dx_min, levels, c.sc->radius_ratio, s->dt, RHOD_REAL_NAME);
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
  if (nsw > 0) /* the particles as set up (rhod_sim_warnings) */
    for (char *line = strtok(simwarn, "\n"); line; line = strtok(NULL, "\n"))
      logline("rhod: warning: %s", line);
  if (missing)
    logline("rhod: warning: %d of the %d snapshots the checkpoint lists are missing from %s; "
            "snapshots.xdmf still names them",
            missing, (int)ck.nsnap, out);

  const double t_end = c.sc->t_end, dout = c.sc->output_every, dprobe = c.sc->probe_every;
  double next_out = 0, next_probe = 0;
  c.next_ck = o->ck_every;
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
  double last_progress = -1;
  int last_decile = -1;
  for (;;) {
    const int done = rhod_schedule_reached(s->t, t_end, dout);
    if (rhod_schedule_reached(s->t, next_probe, dprobe) || done) {
      rhod_probe_values(s, c.probe_vals);
      for (unsigned k = 0; k < c.nprobe_cols; k++)
        if (!isfinite(c.probe_vals[k])) {
          snprintf(err, sizeof err,
                   "unstable at t = %.6g s: probe column %s is not finite (%g); nothing was "
                   "written for this time",
                   s->t, c.probe_names[k], c.probe_vals[k]);
          st = RHOD_ERR_UNSTABLE;
          goto fail;
        }
      st = rhod_csv_row(&c.csv, s->t, c.probe_vals, err, sizeof err);
      if (st != RHOD_OK)
        goto fail;
      next_probe = rhod_schedule_advance(next_probe, dprobe, s->t);
    }
    if (rhod_schedule_reached(s->t, next_out, dout) || done) {
      st = write_output(&c, err, sizeof err);
      if (st != RHOD_OK)
        goto fail;
      logline("rhod: t = %.6g s: snapshot %d (%zu particles)", s->t, c.nsnap - 1, s->p.n);
      next_out = rhod_schedule_advance(next_out, dout, s->t);
    }
    if (done)
      break;
    if ((c.ck_every > 0 && rhod_schedule_reached(s->t, c.next_ck, c.ck_every)) || g_stop) {
      if (c.ck_every > 0)
        c.next_ck = rhod_schedule_advance(c.next_ck, c.ck_every, s->t);
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
    /* land exactly on output times and on the end: a step that would end within a
     * millionth of itself before the target is stretched onto it, and one that would end
     * less than a step before it is halved (tolerances relative to the step, not to the
     * end time) */
    const double stop = fmin(t_end, next_out);
    if (s->t + dt > stop - 1e-6 * dt)
      dt = stop - s->t;
    else if (s->t + 2 * dt > stop)
      dt = 0.5 * (stop - s->t);
    if (!(s->t + dt > s->t)) {
      snprintf(err, sizeof err,
               "the time step %g s is below the resolution of t = %.17g s in double precision: "
               "the run cannot advance (time.end too large against the step?)",
               dt, s->t);
      st = RHOD_ERR_UNSTABLE;
      goto fail;
    }
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
              tty ? "\r\033[K" : "", s->t, 100 * frac, s->p.n, s->dt,
              s->particle_steps / (w > 0 ? w : 1), eta, tty ? "" : "\n");
      fflush(stderr);
      g_progress_shown = tty;
    }
  }
  clear_progress();
  {
    const double wall = now() - t0;
    const double psteps = s->particle_steps;
    logline("rhod: done: %ld steps, %.3f s wall, %.4g us per particle-step", s->step, wall,
            psteps > 0 ? 1e6 * wall / psteps : 0.0);
    /* the scheme's lines (refinement, step limits), then the engine's */
    char lines[4096];
    rhod_warn_buf lb = {lines, sizeof lines, 0, 0};
    lines[0] = '\0';
    rhod_sim_report(s, s->step - c.step0, &lb);
    for (char *line = strtok(lines, "\n"); line; line = strtok(NULL, "\n"))
      logline("rhod: %s", line);
    if (s->reflected)
      logline("rhod: %ld particle-steps ended just behind a wall and were reflected back "
              "(docs/choices.md)",
              s->reflected);
    st = write_summary(&c, "ok", "", wall);
  }
  goto cleanup;
fail:
  report("%s", err);
  if (g_log) {
    char line[2 * ERRLEN];
    one_line(err, line, sizeof line);
    fprintf(g_log, "rhod: error: %s\n", line);
    fflush(g_log);
  }
  write_summary(&c, st == RHOD_ERR_UNSTABLE ? "unstable" : "error", err, now() - t0);
  if (st == RHOD_ERR_UNSTABLE && c.nsnap)
    report("the last good snapshot is %s/snapshot_%04d.h5 (t = %g s)", out, c.nsnap - 1,
           c.snap_t[c.nsnap - 1]);
cleanup:
  /* the handlers stay installed until the process ends: a signal during the clean-up
   * (long under ASan's leak check) must not turn exit 9 into a kill */
  rhod_checkpoint_free(&ck);
  if (c.csv_open) {
    char e2[ERRLEN];
    if (rhod_csv_close(&c.csv, e2, sizeof e2) != RHOD_OK && st == RHOD_OK) {
      report("%s", e2);
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
  if (lockfd >= 0)
    close(lockfd);
  return st;
}

/* ---- rhod check ----------------------------------------------------------------------- */

/* One line per body: its motion, shape and resolved values (src/scene_bodies.c). */
static void print_bodies(const rhod_scene *sc) {
  static const char *const motion[] = {"fixed", "imposed", "free"}, *const dof[] = {"x", "y",
                                                                                    "theta"};
  static const char *const shape[] = {"rect", "polygon", "circle"};
  for (unsigned i = 0; i < sc->n_bodies; i++) {
    const rhod_body *b = &sc->bodies[i];
    printf("body %s (bodies.%u): %s %s, centre [%g, %g], slip %s, refinement near it %s", b->name,
           i, motion[b->motion], shape[b->shape.kind], b->center[0], b->center[1],
           b->slip == RHOD_SLIP_NO ? "no" : "free", b->refine ? "on" : "off");
    if (b->motion == RHOD_MOTION_IMPOSED)
      printf(", at t = 0 moved by [%g, %g] m and turned by %g rad", b->pose0[0], b->pose0[1],
             b->pose0[2]);
    if (b->motion == RHOD_MOTION_FREE) {
      printf(", mass %g kg/m", b->mass);
      if (b->density > 0)
        printf(" (density %g kg/m^3)", b->density);
      printf(", inertia %g kg m", b->inertia);
      if (b->added_mass >= 0)
        printf(", added mass %g kg/m", b->added_mass);
      else
        printf(", added mass rho0 x area");
      printf(", locked:");
      int any = 0;
      for (int k = 0; k < RHOD_NDOF; k++)
        if (b->lock[k])
          printf(" %s", dof[k]), any = 1;
      printf("%s", any ? "" : " none");
    }
    printf("\n");
  }
}

/* One line per open boundary: its kind, name, length, resolved normal and, for an inflow,
 * its velocity law and profile, for an outflow its ambient pressure (src/scene_open.c). */
static void print_open(const rhod_scene *sc) {
  for (unsigned i = 0; i < sc->n_open; i++) {
    const rhod_open_boundary *b = &sc->open[i];
    const int in = b->kind == RHOD_OPEN_INFLOW;
    printf("%s %s (open_boundaries.%u): %g m long, normal [%g, %g], dx %g m",
           in ? "inflow" : "outflow", b->name, i,
           hypot(b->to[0] - b->from[0], b->to[1] - b->from[1]), b->normal[0], b->normal[1], b->dx);
    if (in)
      printf(", velocity %s m/s (%s)", b->velocity,
             b->profile == RHOD_PROFILE_PARABOLIC ? "parabolic, its mean" : "uniform");
    else
      printf(", ambient pressure %g Pa", b->pressure);
    if (b->surface_set)
      printf(", surface %g m", b->surface);
    printf("\n");
  }
}

static int check_scene(run_opts *o) {
  char err[ERRLEN] = "";
  rhod_scene *sc = NULL;
  int st = rhod_scene_load(o->scene, o->sets, o->nsets, &sc, err, sizeof err);
  if (st != RHOD_OK) {
    report("%s", err);
    return st;
  }
  char warn[4096];
  const int nw = rhod_scene_warnings(sc, warn, sizeof warn);
  rhod_sim sim;
  memset(&sim, 0, sizeof sim);
  st = rhod_sim_init(&sim, sc, err, sizeof err);
  char simwarn[4096] = "";
  const int nsw = st == RHOD_OK ? rhod_sim_warnings(&sim, simwarn, sizeof simwarn) : 0;
  if (st == RHOD_OK) {
    rhod_snapshot_view v;
    rhod_sim_fetch(&sim, &v);
    st = rhod_snapshot_check(&v, err, sizeof err);
  }
  if (st != RHOD_OK) {
    report("%s", err);
    rhod_sim_free(&sim);
    rhod_scene_free(sc);
    return st;
  }
  size_t per = 0;
  for (int k = 0; k < sim.p.nfields; k++)
    per += sim.p.fields[k].elem;
  const double bytes = (double)per * (double)sim.p.cap;
  printf("scene: %s\n", sc->path);
  const int levels = sc->rs ? sc->rs->levels : 1; /* refinement.levels (rhodsph) */
  printf("particles: %zu fluid (%d level%s, dx = %g m), %zu ghosts at t = 0\n", sim.p.n, levels,
         levels > 1 ? "s" : "", sc->dx, sim.p.ng);
  printf("memory: %.1f MiB for the particle arrays (%zu bytes per particle, room for %zu)\n",
         bytes / 1048576.0, per, sim.p.cap);
  printf("first time step: %.4g s\n", sim.dt);
  const double steps = sim.dt > 0 ? sc->t_end / sim.dt : 0;
  printf("steps: about %.0f to t = %g s at the first step's size (the step changes with the "
         "flow)\n",
         ceil(steps), sc->t_end);
  printf("outputs: %.0f snapshots, %.0f probe rows\n", floor(sc->t_end / sc->output_every) + 1,
         floor(sc->t_end / sc->probe_every) + 1);
  print_bodies(sc);
  print_open(sc);
  if (nw > 0) {
    char *line = strtok(warn, "\n");
    while (line) {
      printf("warning: %s\n", line);
      line = strtok(NULL, "\n");
    }
  }
  if (nsw > 0)
    for (char *line = strtok(simwarn, "\n"); line; line = strtok(NULL, "\n"))
      printf("warning: %s\n", line);
  rhod_sim_free(&sim);
  rhod_scene_free(sc);
  return RHOD_OK;
}

/* ---- the command line ----------------------------------------------------------------- */

enum { OPT_SET = 256, OPT_CHECKPOINT, OPT_OVERWRITE };

/* Parses the options of run (command 0) or check (command 2); *help set on -h. */
static int parse_opts(int argc, char **argv, int command, run_opts *o, int *help) {
  static const struct option run_long[] = {
      {"output", required_argument, NULL, 'o'},
      {"set", required_argument, NULL, OPT_SET},
      {"checkpoint-every", required_argument, NULL, OPT_CHECKPOINT},
      {"overwrite", no_argument, NULL, OPT_OVERWRITE},
      {"help", no_argument, NULL, 'h'},
      {NULL, 0, NULL, 0}};
  static const struct option check_long[] = {{"set", required_argument, NULL, OPT_SET},
                                             {"help", no_argument, NULL, 'h'},
                                             {NULL, 0, NULL, 0}};
  const int is_run = command == 0;
  const char *name = is_run ? "run" : "check";
  optind = 0; /* a fresh scan */
  opterr = 0;
  *help = 0;
  int ch;
  while ((ch = getopt_long(argc, argv, is_run ? ":o:h" : ":h", is_run ? run_long : check_long,
                           NULL)) != -1) {
    switch (ch) {
    case 'o':
      o->out = optarg;
      break;
    case OPT_SET:
      if (!strchr(optarg, '=') || optarg[0] == '=') {
        report("%s: --set needs dotted.key=value (got '%.200s')", name, optarg);
        return RHOD_ERR_USAGE;
      }
      if (o->nsets >= MAX_SETS) {
        report("%s: too many --set options (%d at most)", name, MAX_SETS);
        return RHOD_ERR_USAGE;
      }
      o->sets[o->nsets++] = optarg;
      break;
    case OPT_CHECKPOINT: {
      char *end = NULL;
      o->ck_every = strtod(optarg, &end);
      if (!end || *end || end == optarg || !(o->ck_every > 0) || !isfinite(o->ck_every)) {
        report("run: --checkpoint-every needs a time in seconds > 0 (got '%.200s')", optarg);
        return RHOD_ERR_USAGE;
      }
      break;
    }
    case OPT_OVERWRITE:
      o->overwrite = 1;
      break;
    case 'h':
      *help = 1;
      return RHOD_OK;
    case ':':
      report("%s: option '%s' needs a value (rhod help %s)", name, argv[optind - 1], name);
      return RHOD_ERR_USAGE;
    default:
      report("%s: unknown option '%s' (rhod help %s)", name, argv[optind - 1], name);
      return RHOD_ERR_USAGE;
    }
  }
  /* GNU getopt_long moves the operands behind the options: the scene, and nothing else */
  if (optind < argc)
    o->scene = argv[optind++];
  if (optind < argc) {
    report("%s: one scene per %s ('%s' is extra)", name, name, argv[optind]);
    return RHOD_ERR_USAGE;
  }
  return RHOD_OK;
}

static int usage_error(const char *msg) {
  report("%s", msg);
  fputs(USAGE, stderr);
  return RHOD_ERR_USAGE;
}

static int cmd_help(const char *topic) {
  if (!topic) {
    fputs(USAGE, stdout);
    fputs("Commands:\n  run      runs a scene (rhod help run)\n"
          "  resume   continues a run from its checkpoint (rhod help resume)\n"
          "  check    validates a scene and estimates the run, writing nothing (rhod help "
          "check)\n",
          stdout);
    return 0;
  }
  if (!strcmp(topic, "run"))
    fputs(HELP_RUN, stdout);
  else if (!strcmp(topic, "resume"))
    fputs(HELP_RESUME, stdout);
  else if (!strcmp(topic, "check"))
    fputs(HELP_CHECK, stdout);
  else {
    report("help: no command '%s' (run, resume, check)", topic);
    return RHOD_ERR_USAGE;
  }
  return 0;
}

/* File descriptors 0, 1 and 2 open (on /dev/null when the caller closed them): a file
 * the run opens must never become stdout or stderr and receive the terminal output. */
static void keep_std_fds(void) {
  for (int fd = 0; fd < 3; fd++)
    if (fcntl(fd, F_GETFD) < 0 && errno == EBADF) {
      int n = open("/dev/null", O_RDWR);
      if (n >= 0 && n != fd) {
        dup2(n, fd);
        close(n);
      }
    }
}

int main(int argc, char **argv) {
  keep_std_fds();
  /* a closed pipe on stdout or stderr (rhod run ... | head) must not kill the run */
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = SIG_IGN;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGPIPE, &sa, NULL);

  if (argc < 2) {
    fputs(USAGE, stderr);
    return RHOD_ERR_USAGE;
  }
  const char *cmd = argv[1];
  if (!strcmp(cmd, "--help") || !strcmp(cmd, "-h"))
    return cmd_help(NULL);
  if (!strcmp(cmd, "help")) {
    if (argc > 3)
      return usage_error("help: one command at most");
    return cmd_help(argc == 3 ? argv[2] : NULL);
  }
  if (!strcmp(cmd, "--version") || !strcmp(cmd, "version")) {
    printf("rhod %s (commit %s, %s precision, %s)\n", rhod_version(), rhod_commit(), RHOD_REAL_NAME,
#ifdef RHOD_OFFLOAD
           "nvptx offload"
#else
           "host OpenMP"
#endif
    );
    return 0;
  }
  static run_opts o; /* static: 256 override pointers */
  memset(&o, 0, sizeof o);
  if (!strcmp(cmd, "run") || !strcmp(cmd, "check")) {
    const int is_run = !strcmp(cmd, "run");
    int help = 0;
    int st = parse_opts(argc - 1, argv + 1, is_run ? 0 : 2, &o, &help);
    if (st != RHOD_OK)
      return st;
    if (help)
      return cmd_help(cmd);
    if (!o.scene)
      return usage_error(is_run ? "run needs a scene file" : "check needs a scene file");
    return is_run ? run(&o, NULL) : check_scene(&o);
  }
  if (!strcmp(cmd, "resume")) {
    if (argc == 3 && (!strcmp(argv[2], "--help") || !strcmp(argv[2], "-h")))
      return cmd_help("resume");
    if (argc != 3 || argv[2][0] == '-')
      return usage_error("resume needs exactly one output folder (rhod help resume)");
    return run(&o, argv[2]);
  }
  report("unknown command '%s'", cmd);
  fputs(USAGE, stderr);
  return RHOD_ERR_USAGE;
}
