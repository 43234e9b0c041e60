/* Whether this processor runs the x86-64-v3 build of the core (AVX2, FMA, BMI2, ...),
   asked of the compiler's runtime (which also checks that the OS saves the AVX state).
   Called through driver/cpu.f90 (py_cpu_level in wrappers.f90); 0 on other machines and
   with compilers that cannot ask (clang, GCC < 12): the portable core is used then. */
int lc_cpu_has_x86_64_v3(void)
{
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && (__GNUC__ >= 12)
    __builtin_cpu_init();
    return __builtin_cpu_supports("x86-64-v3") ? 1 : 0;
#else
    return 0;
#endif
}
