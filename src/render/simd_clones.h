// SPDX-License-Identifier: Apache-2.0
// CAMBIUM_SIMD_CLONES: a function built once per vector width the machine may have, picked
// at load time (GCC's target_clones, an ifunc): AVX-512 with its byte and word instructions
// (x86-64-v4; "avx512f" alone leaves out the byte swaps GCC finds in bit reversals, and
// would not vectorise them at 16 lanes), AVX2, and the baseline processor. For loops of
// plain arithmetic over a fixed count whose clones must give the same bits: integer
// arithmetic, or floating point compiled without FMA contraction (camera.cpp; see
// src/render/CMakeLists.txt). The clones exist only on x86; elsewhere the compiler
// vectorises for what it targets.
#pragma once

#if defined(__x86_64__) || defined(__i386__)
#define CAMBIUM_SIMD_CLONES [[gnu::target_clones("arch=x86-64-v4", "avx2", "default")]]
#else
#define CAMBIUM_SIMD_CLONES
#endif
