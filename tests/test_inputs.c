/* Bounded reads and probes.csv reopening (robustness round 2), below the command line:
 * rhod_read_file refuses devices, FIFOs and directories without blocking and stops at
 * its cap; rhod_csv_check / rhod_csv_reopen never lengthen a probes.csv; the scene
 * loader caps the text aliases expand to, refuses an escaped NUL and keeps its messages
 * on one line. */
#define _XOPEN_SOURCE 700

#include "cunit_main.h"
#include "rhod/io.h"
#include "rhod/scene.h"

#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char dir[] = "/tmp/rhod_test_inputs_XXXXXX";

static const char *tpath(const char *name) {
  static char buf[4][512];
  static int k;
  char *b = buf[k++ % 4];
  snprintf(b, sizeof buf[0], "%s/%s", dir, name);
  return b;
}

static void put_file(const char *path, const char *text) {
  FILE *f = fopen(path, "w");
  CU_ASSERT_PTR_NOT_NULL_FATAL(f);
  fputs(text, f);
  fclose(f);
}

static off_t size_of(const char *path) {
  struct stat st;
  return stat(path, &st) == 0 ? st.st_size : -1;
}

/* ---- rhod_read_file ---- */

static void test_read_regular(void) {
  put_file(tpath("r.txt"), "hello\n");
  char *t = NULL;
  size_t n = 0;
  CU_ASSERT_EQUAL(rhod_read_file(tpath("r.txt"), 6, &t, &n), 0);
  CU_ASSERT_EQUAL(n, 6);
  CU_ASSERT_STRING_EQUAL(t, "hello\n");
  free(t);
  /* one byte over the cap */
  t = NULL;
  CU_ASSERT_EQUAL(rhod_read_file(tpath("r.txt"), 5, &t, &n), RHOD_READ_TOO_LARGE);
  CU_ASSERT_PTR_NULL(t);
  CU_ASSERT_EQUAL(rhod_read_file(tpath("none.txt"), 100, &t, &n), ENOENT);
}

static void test_read_devices(void) {
  char *t = NULL;
  size_t n = 0;
  CU_ASSERT_EQUAL(rhod_read_file("/dev/zero", 1 << 20, &t, &n), RHOD_READ_NOT_REGULAR);
  CU_ASSERT_EQUAL(rhod_read_file("/dev/null", 1 << 20, &t, &n), RHOD_READ_NOT_REGULAR);
  CU_ASSERT_EQUAL(rhod_read_file(dir, 1 << 20, &t, &n), EISDIR);
  CU_ASSERT_PTR_NULL(t);
  CU_ASSERT_STRING_EQUAL(rhod_read_strerror(RHOD_READ_NOT_REGULAR), "not a regular file");
  CU_ASSERT_PTR_NOT_NULL(strstr(rhod_read_strerror(EISDIR), "not a regular file"));
}

static void test_read_fifo(void) {
  const char *f = tpath("fifo");
  CU_ASSERT_FATAL(mkfifo(f, 0600) == 0);
  char *t = NULL;
  size_t n = 0;
  alarm(10); /* a blocking open or read would hang: fail by SIGALRM instead */
  CU_ASSERT_EQUAL(rhod_read_file(f, 1 << 20, &t, &n), RHOD_READ_NOT_REGULAR);
  /* with a writer that never closes */
  const int w = open(f, O_RDWR | O_NONBLOCK);
  CU_ASSERT_FATAL(w >= 0);
  CU_ASSERT_EQUAL(rhod_read_file(f, 1 << 20, &t, &n), RHOD_READ_NOT_REGULAR);
  alarm(0);
  close(w);
  unlink(f);
}

/* ---- probes.csv ---- */

static const char *CSV = "t,a,b\n0,1,2\n0.1,3,4\n0.2,5,6\n";

static void test_csv_shorter_refused(void) {
  const char *p = tpath("probes.csv");
  put_file(p, "t,a,b\n0,1,2\n"); /* 12 bytes */
  char err[512];
  rhod_csv c;
  CU_ASSERT_EQUAL(rhod_csv_check(p, 20, err, sizeof err), RHOD_ERR_CHECKPOINT);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "12 bytes, shorter than the 20 the checkpoint recorded"));
  CU_ASSERT_EQUAL(rhod_csv_reopen(&c, p, 2, 20, err, sizeof err), RHOD_ERR_CHECKPOINT);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "shorter than"));
  CU_ASSERT_EQUAL(size_of(p), 12); /* not padded */
  CU_ASSERT_EQUAL(rhod_csv_reopen(&c, p, 2, (uint64_t)1 << 40, err, sizeof err),
                  RHOD_ERR_CHECKPOINT);
  CU_ASSERT_EQUAL(size_of(p), 12);
  CU_ASSERT_EQUAL(rhod_csv_reopen(&c, p, 2, UINT64_MAX, err, sizeof err), RHOD_ERR_CHECKPOINT);
  CU_ASSERT_EQUAL(size_of(p), 12);
}

static void test_csv_reopen_cuts_and_appends(void) {
  const char *p = tpath("probes.csv");
  put_file(p, CSV);
  char err[512];
  rhod_csv c;
  CU_ASSERT_EQUAL(rhod_csv_check(p, 20, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL_FATAL(rhod_csv_reopen(&c, p, 2, 20, err, sizeof err), RHOD_OK); /* 2 rows */
  const double v[2] = {7, 8};
  CU_ASSERT_EQUAL(rhod_csv_row(&c, 0.5, v, err, sizeof err), RHOD_OK);
  CU_ASSERT_EQUAL(rhod_csv_close(&c, err, sizeof err), RHOD_OK);
  char buf[128] = "";
  FILE *f = fopen(p, "r");
  CU_ASSERT_PTR_NOT_NULL_FATAL(f);
  buf[fread(buf, 1, sizeof buf - 1, f)] = '\0';
  fclose(f);
  CU_ASSERT_STRING_EQUAL(buf, "t,a,b\n0,1,2\n0.1,3,4\n0.5,7,8\n");
}

static void test_csv_wrong_file_refused(void) {
  const char *p = tpath("probes.csv");
  char err[512];
  rhod_csv c;
  put_file(p, CSV);
  CU_ASSERT_EQUAL(rhod_csv_reopen(&c, p, 3, 18, err, sizeof err), RHOD_ERR_CHECKPOINT);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "header"));
  CU_ASSERT_EQUAL(rhod_csv_check(p, 17, err, sizeof err), RHOD_ERR_CHECKPOINT); /* mid-row */
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "does not end a row"));
  put_file(p, "time,a,b\n0,1,2\n");
  CU_ASSERT_EQUAL(rhod_csv_check(p, 15, err, sizeof err), RHOD_ERR_CHECKPOINT);
  CU_ASSERT_EQUAL(rhod_csv_check(tpath("nothing.csv"), 15, err, sizeof err), RHOD_ERR_CHECKPOINT);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "missing"));
  const char *fifo = tpath("probes_fifo.csv");
  CU_ASSERT_FATAL(mkfifo(fifo, 0600) == 0);
  alarm(10);
  CU_ASSERT_EQUAL(rhod_csv_check(fifo, 15, err, sizeof err), RHOD_ERR_CHECKPOINT);
  CU_ASSERT_EQUAL(rhod_csv_reopen(&c, fifo, 2, 15, err, sizeof err), RHOD_ERR_CHECKPOINT);
  alarm(0);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "not a regular file"));
  unlink(fifo);
}

/* ---- the scene loader ---- */

static const char *MINIMAL = "time: {end: 1, output_every: 0.1}\n"
                             "particles: {dx: 0.1}\n"
                             "physics: {c0: 10}\n"
                             "fluid:\n"
                             "  - rect: {min: [0, 0], max: [1, 1]}\n";

/* Loads text (+ overrides) and expects an error whose message holds `want`, on one line. */
static void scene_fails(const char *text, const char *const *ov, int nov, int code,
                        const char *want) {
  const char *p = tpath("scene.yaml");
  put_file(p, text);
  rhod_scene *s = NULL;
  char err[1024] = "";
  const int rc = rhod_scene_load(p, ov, nov, &s, err, sizeof err);
  CU_ASSERT_EQUAL(rc, code);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, want));
  CU_ASSERT_PTR_NULL(strpbrk(err, "\n\r\t"));
  if (rc != code || !strstr(err, want))
    printf("\n  wanted '%s', got %d: %s\n", want, rc, err);
  rhod_scene_free(s);
}

static void test_scene_nul(void) {
  char text[512];
  snprintf(text, sizeof text, "%sname: \"a\\0b\"\n", MINIMAL);
  scene_fails(text, NULL, 0, RHOD_ERR_SCENE, "scene.yaml:6:7: name: a NUL character");
  snprintf(text, sizeof text, "%s\"k\\0\": 1\n", MINIMAL);
  scene_fails(text, NULL, 0, RHOD_ERR_SCENE, "scene.yaml:6:1:");
  const char *ov[] = {"name=\"x\\0\""};
  scene_fails(MINIMAL, ov, 1, RHOD_ERR_SCENE, "--set name=\"x\\0\": name: invalid YAML value");
}

/* Few nodes, gigabytes of text: refused at the alias that crosses 64 MiB. */
static void test_scene_alias_bytes(void) {
  const size_t big = 100000;
  char *text = malloc(big + 4096);
  CU_ASSERT_PTR_NOT_NULL_FATAL(text);
  size_t n = (size_t)sprintf(text, "a: &a \"");
  memset(text + n, 'y', big);
  n += big;
  n += (size_t)sprintf(text + n, "\"\nb: &b [*a");
  for (int i = 1; i < 100; i++)
    n += (size_t)sprintf(text + n, ", *a");
  n += (size_t)sprintf(text + n, "]\nc: &c [*b");
  for (int i = 1; i < 100; i++)
    n += (size_t)sprintf(text + n, ", *b");
  sprintf(text + n, "]\n");
  scene_fails(text, NULL, 0, RHOD_ERR_SCENE, "scene.yaml:3:");
  scene_fails(text, NULL, 0, RHOD_ERR_SCENE, "aliases expand to more than 64 MiB of text");
  free(text);
}

static void test_scene_file_kinds(void) {
  rhod_scene *s = NULL;
  char err[1024];
  CU_ASSERT_EQUAL(rhod_scene_load("/dev/zero", NULL, 0, &s, err, sizeof err), RHOD_ERR_READ);
  CU_ASSERT_STRING_EQUAL(err, "/dev/zero: cannot read: not a regular file");
  CU_ASSERT_EQUAL(rhod_scene_load(dir, NULL, 0, &s, err, sizeof err), RHOD_ERR_READ);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "not a regular file"));
  /* 16 MiB and one byte */
  const char *p = tpath("big.yaml");
  FILE *f = fopen(p, "w");
  CU_ASSERT_PTR_NOT_NULL_FATAL(f);
  CU_ASSERT(fseek(f, (16L << 20), SEEK_SET) == 0 && fputc('#', f) != EOF);
  fclose(f);
  CU_ASSERT_EQUAL(rhod_scene_load(p, NULL, 0, &s, err, sizeof err), RHOD_ERR_READ);
  CU_ASSERT_PTR_NOT_NULL(strstr(err, "big.yaml: cannot read: larger than 16 MiB"));
  unlink(p);
}

static void test_scene_long_override(void) {
  static const size_t lens[] = {300, 5000, 100000};
  for (int i = 0; i < 3; i++) {
    char *ov = malloc(lens[i] + 32);
    CU_ASSERT_PTR_NOT_NULL_FATAL(ov);
    int n = sprintf(ov, "particles.kernel=");
    memset(ov + n, 'q', lens[i]);
    ov[n + (int)lens[i]] = '\0';
    const char *ovs[] = {ov};
    scene_fails(MINIMAL, ovs, 1, RHOD_ERR_SCENE, ": particles.kernel: invalid value 'qqq");
    scene_fails(MINIMAL, ovs, 1, RHOD_ERR_SCENE, "--set particles.kernel=qqq");
    free(ov);
  }
}

static void test_scene_control_chars(void) {
  char text[512];
  snprintf(text, sizeof text, "%s\"a\\nb\\x1b\": 1\n", MINIMAL);
  scene_fails(text, NULL, 0, RHOD_ERR_SCENE, "scene.yaml:6:1: a\\nb\\x1B: unknown key");
  const char *ov[] = {"name=x\ny\tz"};
  scene_fails(MINIMAL, ov, 1, RHOD_ERR_SCENE, "--set name=x\\ny\\tz: name:");
}

int main(void) {
  if (!mkdtemp(dir))
    return 2;
  static const rhod_test_case cases[] = {
      {"read: a regular file, its cap", test_read_regular},
      {"read: devices and a directory refused", test_read_devices},
      {"read: a FIFO refused without blocking", test_read_fifo},
      {"probes.csv shorter than recorded: refused, not padded", test_csv_shorter_refused},
      {"probes.csv reopened: cut at the row, appended", test_csv_reopen_cuts_and_appends},
      {"probes.csv of another run refused", test_csv_wrong_file_refused},
      {"scene: an escaped NUL", test_scene_nul},
      {"scene: aliases expanding to gigabytes", test_scene_alias_bytes},
      {"scene: a device, a directory, a file over 16 MiB", test_scene_file_kinds},
      {"scene: long --set values keep the override and the reason", test_scene_long_override},
      {"scene: control characters escaped", test_scene_control_chars},
  };
  const int rc = RHOD_RUN_TESTS("inputs", cases);
  char cmd[600];
  snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
  if (system(cmd) != 0)
    return rc ? rc : 1;
  return rc;
}
