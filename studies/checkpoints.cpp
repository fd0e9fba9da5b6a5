#include "rfem/studies/checkpoints.hpp"

#include <cstdint>
#include <stdexcept>

namespace rfem {

namespace {

constexpr double kVersion = 1.0;

double key_hash(const std::string& key) {  // FNV-1a, 32 bits: exact as a double
  uint32_t h = 2166136261u;
  for (unsigned char c : key) h = (h ^ c) * 16777619u;
  return static_cast<double>(h);
}

}  // namespace

void put_block(std::vector<double>& x, const std::vector<double>& block) {
  x.push_back(static_cast<double>(block.size()));
  x.insert(x.end(), block.begin(), block.end());
}

std::vector<double> take_block(const std::vector<double>& x, size_t& i, const std::string& what) {
  if (i >= x.size() || !(x[i] >= 0) || x[i] > static_cast<double>(x.size() - i - 1)) throw std::invalid_argument(what);
  const size_t n = static_cast<size_t>(x[i++]);
  std::vector<double> v(x.begin() + static_cast<long>(i), x.begin() + static_cast<long>(i + n));
  i += n;
  return v;
}

const std::vector<double>* RunState::find(const std::string& key) const {
  const double h = key_hash(key);
  for (const auto& [k, v] : observers)
    if (k == h) return &v;
  return nullptr;
}

void RunState::add(const std::string& key, std::vector<double> state) { observers.emplace_back(key_hash(key), std::move(state)); }

std::vector<double> RunState::pack() const {
  std::vector<double> x = {kVersion};
  put_block(x, integrator.pack());
  put_block(x, summary);
  x.push_back(static_cast<double>(observers.size()));
  for (const auto& [k, v] : observers) {
    x.push_back(k);
    put_block(x, v);
  }
  return x;
}

RunState RunState::unpack(const std::vector<double>& x, int unknowns) {
  size_t i = 0;
  const std::string why = "the checkpoint is damaged or from another version of rfem";
  auto bad = [&] { return std::invalid_argument(why); };
  auto block = [&] { return take_block(x, i, why); };
  if (x.empty() || x[0] != kVersion) throw bad();
  i = 1;
  RunState s;
  s.integrator = IntegratorState::unpack(block(), unknowns);
  s.summary = block();
  if (i >= x.size()) throw bad();
  const double count = x[i++];
  for (double k = 0; k < count; ++k) {
    if (i >= x.size()) throw bad();
    const double key = x[i++];
    s.observers.emplace_back(key, block());
  }
  if (i != x.size()) throw bad();
  return s;
}

}  // namespace rfem
