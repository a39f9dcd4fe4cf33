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
 * every processor when the variants are not built); the environment's
 * POUND_ISA = baseline, avx2 or avx512 caps it (benchmarks and tests run
 * each variant this way). */
int pd_cpu_level(void);
/* The level an instruction set's name stands for (POUND_ISA's values):
 * "baseline" 0, "avx2" 3, "avx512" 4; -1 for any other name. */
int pd_cpu_isa_parse(const char *name);
/* "avx512 (x86-64-v4)", "avx2 (x86-64-v3)", "baseline". */
const char *pd_cpu_level_name(int level);

#endif
