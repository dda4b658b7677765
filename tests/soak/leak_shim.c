// A leak to show that the soak's judgement can fail: preloaded into facetd (LD_PRELOAD), it
// leaks each time a .png file is opened (once per replayed part, and per archived image):
//   FACET_LEAK_KB=n   n KiB of heap, written so that it is resident
//   FACET_LEAK_FDS=1  one file descriptor (a dup of stderr)
// Without either variable it only passes the calls on.
#define _GNU_SOURCE
#include <dlfcn.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static char* volatile leaked;  // keeps the compiler from dropping the unused allocation

static void leak(const char* path) {
  const size_t n = path ? strlen(path) : 0;
  if (n < 4 || strcmp(path + n - 4, ".png") != 0) return;
  const char* kib = getenv("FACET_LEAK_KB");
  if (kib) {
    const size_t bytes = (size_t)atol(kib) * 1024;
    char* p = malloc(bytes);
    if (p) memset(p, 1, bytes);
    leaked = p;
  }
  if (getenv("FACET_LEAK_FDS")) (void)dup(2);
}

typedef int (*OpenFn)(const char*, int, ...);
typedef FILE* (*FopenFn)(const char*, const char*);

// dlsym returns an object pointer; ISO C has no cast to a function pointer, a copy does it.
static void nextSymbol(const char* name, void* fn, size_t size) {
  void* symbol = dlsym(RTLD_NEXT, name);
  memcpy(fn, &symbol, size);
}

static int forwardOpen(const char* name, const char* path, int flags, mode_t mode) {
  OpenFn next;
  nextSymbol(name, &next, sizeof next);
  leak(path);
  return next(path, flags, mode);
}

static FILE* forwardFopen(const char* name, const char* path, const char* mode) {
  FopenFn next;
  nextSymbol(name, &next, sizeof next);
  leak(path);
  return next(path, mode);
}

int open(const char* path, int flags, ...) {
  va_list ap;
  va_start(ap, flags);
  const mode_t mode = (mode_t)va_arg(ap, int);
  va_end(ap);
  return forwardOpen("open", path, flags, mode);
}

int open64(const char* path, int flags, ...) {
  va_list ap;
  va_start(ap, flags);
  const mode_t mode = (mode_t)va_arg(ap, int);
  va_end(ap);
  return forwardOpen("open64", path, flags, mode);
}

FILE* fopen(const char* path, const char* mode) {
  return forwardFopen("fopen", path, mode);
}

FILE* fopen64(const char* path, const char* mode) {
  return forwardFopen("fopen64", path, mode);
}
