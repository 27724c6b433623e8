#include "core/features/brief_pattern.hpp"

#include <cmath>
#include <random>

namespace hiveslam::features {

const std::vector<std::array<int, 4>>& briefPattern() {
  static const std::vector<std::array<int, 4>> pattern = [] {
    std::mt19937 rng(20261122);
    std::normal_distribution<double> g(0.0, 31.0 / 5.0);
    auto point = [&](int& x, int& y) {
      do {
        x = static_cast<int>(std::lround(g(rng)));
        y = static_cast<int>(std::lround(g(rng)));
      } while (x * x + y * y > 13 * 13);
    };
    std::vector<std::array<int, 4>> p;
    while (p.size() < 256) {
      std::array<int, 4> a{};
      point(a[0], a[1]);
      point(a[2], a[3]);
      if (a[0] == a[2] && a[1] == a[3]) continue;  // a test against itself carries no bit
      p.push_back(a);
    }
    return p;
  }();
  return pattern;
}

}  // namespace hiveslam::features
