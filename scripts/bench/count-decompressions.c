// LD_PRELOAD counter of bag chunk decompressions (docs/CHANGELOG.md, "Reading bags (issue 23)"):
// prints at exit how often bz2 and lz4 decompression started. rosbag_storage's one-shot calls
// (BZ2_bzBuffToBuffDecompress, roslz4_buffToBuffDecompress) start a stream internally, so the
// stream counts are the total decompressions (kfd's own and rosbag_storage's).
//   gcc -shared -fPIC -O2 -o count.so scripts/bench/count-decompressions.c -ldl
//   LD_PRELOAD=./count.so build/apps/kfd-filter -q -i X.bag -o Y.bag
#define _GNU_SOURCE
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>

static long n_bz2_oneshot, n_bz2_streams, n_lz4_oneshot, n_lz4_streams;

static void report(void) {
    fprintf(stderr,
            "[count] bz2 buff2buff %ld, bz2 stream inits %ld, lz4 buff2buff %ld, lz4 stream "
            "starts %ld\n",
            n_bz2_oneshot, n_bz2_streams, n_lz4_oneshot, n_lz4_streams);
}
__attribute__((constructor)) static void init(void) { atexit(report); }

int BZ2_bzBuffToBuffDecompress(char* d, unsigned* dl, char* s, unsigned sl, int small, int verb) {
    static int (*real)(char*, unsigned*, char*, unsigned, int, int);
    if (!real) real = dlsym(RTLD_NEXT, "BZ2_bzBuffToBuffDecompress");
    ++n_bz2_oneshot;
    return real(d, dl, s, sl, small, verb);
}
int BZ2_bzDecompressInit(void* s, int v, int small) {
    static int (*real)(void*, int, int);
    if (!real) real = dlsym(RTLD_NEXT, "BZ2_bzDecompressInit");
    ++n_bz2_streams;
    return real(s, v, small);
}
int roslz4_buffToBuffDecompress(char* a, unsigned b, char* c, unsigned* d) {
    static int (*real)(char*, unsigned, char*, unsigned*);
    if (!real) real = dlsym(RTLD_NEXT, "roslz4_buffToBuffDecompress");
    ++n_lz4_oneshot;
    return real(a, b, c, d);
}
int roslz4_decompressStart(void* s) {
    static int (*real)(void*);
    if (!real) real = dlsym(RTLD_NEXT, "roslz4_decompressStart");
    ++n_lz4_streams;
    return real(s);
}
