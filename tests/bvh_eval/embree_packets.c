/* embree_packets - Embree 3 with 16-ray packets on the ground-truth benchmark scene (issue 6).
 *
 * The reference figure is "Embree 3 with 16-ray packets: 11.9 M rays per CPU-second on this
 * machine". This program measures that figure on the scene files that
 * `FABKIT_GT_KEEP=1 scripts/bench-groundtruth` keeps (vertices.npy, triangles.npy, rays.npy:
 * float32, C order), so that fabkit, Open3D and Embree packets can be compared in one run.
 * `scripts/bench-groundtruth --embree` builds and runs it (Debian: apt-get install libembree-dev).
 *
 * Rays go in 4 x 4 pixel blocks (coherent packets, Embree's best case for camera rays), one thread,
 * CPU time of the thread (CLOCK_THREAD_CPUTIME_ID), best of REPS; the hierarchy build (Embree's
 * default quality) is not timed. Rays with a zero direction (pixels outside the camera's field)
 * are masked off. Prints one JSON line: best_cpu_s, rays, hits, embree_version.
 *
 * Usage: embree_packets DIR WIDTH REPS
 */
#include <embree3/rtcore.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static float *read_npy(const char *dir, const char *name, size_t *count) {
  char path[4096];
  snprintf(path, sizeof path, "%s/%s", dir, name);
  FILE *f = fopen(path, "rb");
  if (!f) { perror(path); exit(2); }
  unsigned char head[10];
  if (fread(head, 1, 10, f) != 10 || memcmp(head, "\x93NUMPY\x01\x00", 8) != 0) {
    fprintf(stderr, "%s: not a version 1 .npy file\n", path);
    exit(2);
  }
  size_t hlen = head[8] | (head[9] << 8);
  char *h = malloc(hlen + 1);
  if (fread(h, 1, hlen, f) != hlen) { fprintf(stderr, "%s: short header\n", path); exit(2); }
  h[hlen] = 0;
  if (!strstr(h, "'<f4'") || strstr(h, "'fortran_order': True")) {
    fprintf(stderr, "%s: expected little-endian float32 in C order\n", path);
    exit(2);
  }
  free(h);
  long start = ftell(f);
  fseek(f, 0, SEEK_END);
  size_t bytes = (size_t)(ftell(f) - start);
  fseek(f, start, SEEK_SET);
  float *data = malloc(bytes);
  if (fread(data, 1, bytes, f) != bytes) { fprintf(stderr, "%s: short data\n", path); exit(2); }
  fclose(f);
  *count = bytes / sizeof(float);
  return data;
}

static double cpu_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + ts.tv_nsec * 1e-9;
}

int main(int argc, char **argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: embree_packets DIR WIDTH REPS\n");
    return 2;
  }
  const char *dir = argv[1];
  int width = atoi(argv[2]), reps = atoi(argv[3]);
  size_t nv, nt, nr;
  float *v = read_npy(dir, "vertices.npy", &nv);
  float *t = read_npy(dir, "triangles.npy", &nt);
  float *r = read_npy(dir, "rays.npy", &nr);
  nv /= 3; nt /= 3; nr /= 6;
  int height = (int)(nr / (size_t)width);
  if (width <= 0 || (size_t)width * (size_t)height != nr || reps <= 0) {
    fprintf(stderr, "WIDTH must divide the %zu rays; REPS > 0\n", nr);
    return 2;
  }

  RTCDevice dev = rtcNewDevice("threads=1");
  RTCScene scene = rtcNewScene(dev);
  RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
  float *vb = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                      3 * sizeof(float), nv);
  memcpy(vb, v, nv * 3 * sizeof(float));
  unsigned *ib = rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                         3 * sizeof(unsigned), nt);
  for (size_t i = 0; i < 3 * nt; i++) ib[i] = (unsigned)t[i];
  rtcCommitGeometry(g);
  rtcAttachGeometry(scene, g);
  rtcReleaseGeometry(g);
  rtcCommitScene(scene);

  struct RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  double best = INFINITY;
  size_t hits = 0;
  struct RTCRayHit16 rh;
  int valid[16];
  for (int rep = 0; rep < reps; rep++) {
    size_t h_count = 0;
    double t0 = cpu_s();
    for (int by = 0; by < height; by += 4) {
      for (int bx = 0; bx < width; bx += 4) {
        for (int k = 0; k < 16; k++) {
          int x = bx + (k & 3), y = by + (k >> 2);
          valid[k] = 0;
          if (x >= width || y >= height) continue;
          const float *q = r + 6 * ((size_t)y * width + x);
          rh.ray.org_x[k] = q[0]; rh.ray.org_y[k] = q[1]; rh.ray.org_z[k] = q[2];
          rh.ray.dir_x[k] = q[3]; rh.ray.dir_y[k] = q[4]; rh.ray.dir_z[k] = q[5];
          rh.ray.tnear[k] = 0.0f;
          rh.ray.tfar[k] = INFINITY;
          rh.ray.time[k] = 0.0f;
          rh.ray.mask[k] = 0xFFFFFFFFu;
          rh.ray.flags[k] = 0;
          rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
          valid[k] = (q[3] != 0.0f || q[4] != 0.0f || q[5] != 0.0f) ? -1 : 0;
        }
        rtcIntersect16(valid, scene, &ctx, &rh);
        for (int k = 0; k < 16; k++)
          if (valid[k] && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID) h_count++;
      }
    }
    double dt = cpu_s() - t0;
    if (dt < best) best = dt;
    hits = h_count;
  }
  printf("{\"best_cpu_s\": %.9f, \"rays\": %zu, \"hits\": %zu, \"embree_version\": \"%d.%d.%d\"}\n",
         best, nr, hits, RTC_VERSION_MAJOR, RTC_VERSION_MINOR, RTC_VERSION_PATCH);
  rtcReleaseScene(scene);
  rtcReleaseDevice(dev);
  return 0;
}
