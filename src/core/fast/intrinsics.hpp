// The x86 intrinsics (<immintrin.h>), included once for the whole core.
// GCC 12 reports -Wmaybe-uninitialized inside its own AVX-512 intrinsics (the deliberately
// undefined pass-through operand of _mm512_sqrt_pd and friends) wherever one is inlined into our
// code; the location is the system header, so the warning is silenced for the header's lines only
// and stays on for ours. Other compilers (clang builds the fuzz target) include it plainly.
#pragma once

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <immintrin.h>
#pragma GCC diagnostic pop
#else
#include <immintrin.h>
#endif
