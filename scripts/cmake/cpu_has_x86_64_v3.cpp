// Configure-time check (CMakeLists.txt, HMPM_ARCH=auto): exits 0 when the
// machine running the build can execute x86-64-v3 code (AVX2, FMA, BMI2...).
int main() { return __builtin_cpu_supports("x86-64-v3") ? 0 : 1; }
