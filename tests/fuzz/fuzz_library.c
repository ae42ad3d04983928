/* fuzz_library.c - the library itself, for every libFuzzer target: the one
   translation unit that defines TILEDTEX_IMPLEMENTATION. tests/fuzz/run.sh
   compiles it once (with the targets' sanitizers and coverage) and links each
   target against that object, instead of compiling the whole header with the
   sanitizers once per target; a target built by hand just lists this file
   beside its own (see each target's "Build" line). */
#define TILEDTEX_IMPLEMENTATION
#include "tiledtex.h"
