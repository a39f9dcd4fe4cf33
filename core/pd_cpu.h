/* pd_cpu.h — which instruction set runs the library's vector kernels
 * (library-private): the texts compiled once per x86-64 level with GCC
 * (engine/mj_batch_x86v*.c, problems/osc_batch_x86v*.c), the baseline
 * elsewhere, and the level of this processor. */
#ifndef PD_CPU_H
#define PD_CPU_H

#if defined(__GNUC__) && !defined(__clang__) && defined(__x86_64__) && !defined(PD_NO_VARIANTS)
#define PD_X86_VARIANTS 1
#else
#define PD_X86_VARIANTS 0
#endif

/* 4: x86-64-v4 (AVX-512), 3: x86-64-v3 (AVX2), 0: the baseline (and
 * every processor when the variants are not built). */
int pd_cpu_level(void);

#endif
