/* Whether this processor runs the x86-64-v3 build of the core (AVX2, FMA, BMI2, ...),
   asked of the compiler's runtime (which also checks that the OS saves the AVX state).
   Called from wrappers.f90 (py_cpu_level); 0 on other machines and compilers. */
int lc_cpu_has_x86_64_v3(void)
{
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && (__GNUC__ >= 12)
    __builtin_cpu_init();
    return __builtin_cpu_supports("x86-64-v3") ? 1 : 0;
#else
    return 0;
#endif
}
