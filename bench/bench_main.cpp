// ofv_bench: Google Benchmark entry point; cases live in bench_*.cpp.
#include <benchmark/benchmark.h>

BENCHMARK_MAIN();
