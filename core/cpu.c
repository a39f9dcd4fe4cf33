/* cpu.c — the instruction-set level of this processor (pd_cpu.h). */
#include "pd_cpu.h"

int pd_cpu_level(void)
{
#if PD_X86_VARIANTS
    if (__builtin_cpu_supports("x86-64-v4"))
        return 4;
    if (__builtin_cpu_supports("x86-64-v3"))
        return 3;
#endif
    return 0;
}
