// Greedy edge colouring of one kind of spring (spring_colouring.hpp).
#include "spring_colouring.hpp"

namespace clothsim::detail {

Colouring colour_springs(const Model& m, std::uint8_t kind) {
  constexpr int kSerial = 63;
  std::vector<std::uint64_t> used(m.mass_count(), 0);
  std::vector<std::uint8_t> colour(m.spring_count(), kSerial + 1);
  std::vector<std::uint32_t> count(kSerial + 1, 0);
  for (std::size_t s = 0; s < m.spring_count(); ++s) {
    const std::uint32_t a = m.spring_a[s], b = m.spring_b[s];
    if (m.spring_kind[s] != kind || !(m.spring_stiffness(s) > 0.0) || m.inv_mass[a] + m.inv_mass[b] == 0.0) continue;
    const std::uint64_t taken = used[a] | used[b];
    const int c = ~taken & ((std::uint64_t{1} << kSerial) - 1) ? __builtin_ctzll(~taken) : kSerial;
    colour[s] = static_cast<std::uint8_t>(c);
    if (c < kSerial) used[a] |= std::uint64_t{1} << c, used[b] |= std::uint64_t{1} << c;
    ++count[static_cast<std::size_t>(c)];
  }
  Colouring out;
  out.start.assign(kSerial + 2, 0);
  for (std::size_t c = 0; c <= kSerial; ++c) out.start[c + 1] = out.start[c] + count[c];
  out.links.resize(out.start.back());
  std::vector<std::uint32_t> fill(out.start.begin(), out.start.end() - 1);
  for (std::size_t s = 0; s < m.spring_count(); ++s)
    if (colour[s] <= kSerial) {
      const double rest = m.rest_length0[static_cast<Eigen::Index>(s)];
      out.links[fill[colour[s]]++] = Link{m.spring_a[s], m.spring_b[s], rest, m.spring_stiffness(s)};
    }
  return out;
}

}  // namespace clothsim::detail
