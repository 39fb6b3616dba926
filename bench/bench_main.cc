// main() of every benchmark: the process settings of the `monomap` binary
// (util/runtime.h), so that benchmark figures are those of the real tool.
#include <benchmark/benchmark.h>

#include "monomap/util/runtime.h"

int main(int argc, char** argv) {
  monomap::ConfigureRuntime();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
