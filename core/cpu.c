/* cpu.c — the instruction-set level of this processor (pd_cpu.h). */
#include <stdlib.h>
#include <string.h>

#include "pd_cpu.h"

int pd_cpu_isa_parse(const char *name)
{
    if (!strcmp(name, "baseline"))
        return 0;
    if (!strcmp(name, "avx2"))
        return 3;
    if (!strcmp(name, "avx512"))
        return 4;
    return -1;
}

/* The level POUND_ISA asks for, or -1 when it is unset or names none. */
static int requested_level(void)
{
    const char *isa = getenv("POUND_ISA");
    return isa ? pd_cpu_isa_parse(isa) : -1;
}

/* The processor's level, capped by POUND_ISA (benchmarks and tests run each
 * variant the processor has; a level above the processor's is ignored). */
int pd_cpu_level(void)
{
    int level = 0, want = requested_level();
#if PD_X86_VARIANTS
    if (__builtin_cpu_supports("x86-64-v4"))
        level = 4;
    else if (__builtin_cpu_supports("x86-64-v3"))
        level = 3;
#endif
    return want >= 0 && want < level ? want : level;
}

const char *pd_cpu_level_name(int level)
{
    return level == 4 ? "avx512 (x86-64-v4)" : level == 3 ? "avx2 (x86-64-v3)" : "baseline";
}
