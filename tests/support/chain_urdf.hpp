#pragma once

// URDF text of long serial chains, for the size tests of the loaders and base parameters and for
// bench/model/model_bench.cpp.

#include <random>
#include <sstream>
#include <string>

namespace dynid::testing {

/// A serial chain of `moving` revolute joints with pseudo-random origins (rpy and xyz), axes and
/// physical box inertias (fixed `seed`); after each moving joint, `fixed_per_link` fixed joints
/// carry extra small bodies (merged by the loader), so the link depth is moving·(1 +
/// fixed_per_link).
inline std::string chain_urdf(int moving, unsigned seed, int fixed_per_link = 0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::ostringstream x;
  x.precision(17);
  x << "<robot name=\"chain" << moving << "\">\n<link name=\"base\"/>\n";
  auto inertial = [&](double m) {
    const double a = 0.05 + 0.05 * (1 + u(rng)), b = 0.05 + 0.05 * (1 + u(rng)),
                 c = 0.05 + 0.05 * (1 + u(rng));
    x << "<inertial><origin xyz=\"" << 0.1 * u(rng) << " " << 0.1 * u(rng) << " " << 0.1 * u(rng)
      << "\" rpy=\"" << u(rng) << " " << u(rng) << " " << u(rng) << "\"/><mass value=\"" << m
      << "\"/><inertia ixx=\"" << m * (b * b + c * c) / 12 << "\" ixy=\"0\" ixz=\"0\" iyy=\""
      << m * (a * a + c * c) / 12 << "\" iyz=\"0\" izz=\"" << m * (a * a + b * b) / 12
      << "\"/></inertial>";
  };
  std::string parent = "base";
  int k = 0;
  for (int j = 0; j < moving; ++j) {
    for (int f = -1; f < fixed_per_link; ++f, ++k) {
      const std::string link = "l" + std::to_string(k);
      x << "<link name=\"" << link << "\">";
      inertial(f < 0 ? 1.0 + 0.5 * (1 + u(rng)) : 0.01);
      x << "</link>\n<joint name=\"j" << k << "\" type=\"" << (f < 0 ? "revolute" : "fixed")
        << "\"><parent link=\"" << parent << "\"/><child link=\"" << link << "\"/><origin xyz=\""
        << 0.3 * u(rng) << " " << 0.3 * u(rng) << " " << 0.3 * u(rng) << "\" rpy=\"" << u(rng)
        << " " << u(rng) << " " << u(rng) << "\"/>";
      if (f < 0) {
        x << "<axis xyz=\"" << u(rng) << " " << u(rng) << " " << u(rng)
          << "\"/><limit lower=\"-3\" upper=\"3\" effort=\"100\" velocity=\"2\"/>";
      }
      x << "</joint>\n";
      parent = link;
    }
  }
  x << "</robot>\n";
  return x.str();
}

}  // namespace dynid::testing
