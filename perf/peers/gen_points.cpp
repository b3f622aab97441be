// gen_points DIST N SEED OUT — writes the points and Stokeslet densities that
// `fmm_bench --dist DIST --n N --seed SEED` generates itself (tests/fmm/points.hpp:
// make_points(DIST, N, SEED), random_density(3 N, SEED + 1)) in fmm_bench's --input format
// ("N 0", then N lines "x y z f1 f2 f3", %.17g; targets = sources).
#include <cstdio>
#include <cstdlib>
#include <string>

#include "points.hpp"

int main(int argc, char** argv) {
  if (argc != 5) { std::fprintf(stderr, "usage: %s sphere|spheroid|cube|clustered N SEED OUT\n", argv[0]); return 2; }
  const std::string dist = argv[1];
  const std::size_t n = static_cast<std::size_t>(std::atof(argv[2]));
  const unsigned seed = static_cast<unsigned>(std::strtoul(argv[3], nullptr, 10));
  const auto p = capsflow::fmm::testing::make_points(dist, n, seed);
  const auto f = capsflow::fmm::testing::random_density(3 * n, seed + 1);
  std::FILE* o = std::fopen(argv[4], "w");
  if (!o) { std::perror(argv[4]); return 2; }
  std::fprintf(o, "%zu 0\n", n);
  for (std::size_t i = 0; i < n; ++i)
    std::fprintf(o, "%.17g %.17g %.17g %.17g %.17g %.17g\n", p[3 * i], p[3 * i + 1], p[3 * i + 2], f[3 * i],
                 f[3 * i + 1], f[3 * i + 2]);
  return std::fclose(o) == 0 ? 0 : 2;
}
