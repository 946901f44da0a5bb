/* The C hosts' check: a failed condition is printed with its place and counted in `failures`,
 * and the host goes on (each test program includes this once). */
#ifndef EMPM_TEST_CHECK_H
#define EMPM_TEST_CHECK_H
#include <stdio.h>

static int failures = 0;
#define CHECK(cond)                                                             \
  do {                                                                          \
    if (!(cond)) {                                                              \
      fprintf(stderr, "%s:%d: check failed: %s\n", __FILE__, __LINE__, #cond); \
      failures++;                                                               \
    }                                                                           \
  } while (0)

#endif
