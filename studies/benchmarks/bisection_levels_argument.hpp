// The C++ benchmarks' command line: the uniform bisection levels of the blocks to run.
#pragma once

#include <cstdlib>
#include <vector>

namespace snede::benchmarks {

// Each argument a number of uniform bisections of the 16³ Kuhn block; none given: 0 and 2.
inline std::vector<int> bisection_levels_argument(int argc, char** argv) {
  std::vector<int> levels;
  for (int i = 1; i < argc; ++i) levels.push_back(std::atoi(argv[i]));
  if (levels.empty()) levels = {0, 2};
  return levels;
}

}  // namespace snede::benchmarks
