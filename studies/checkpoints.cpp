#include "checkpoints.hpp"

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

PackedState::PackedState(const IntegratorState& integrator, const std::vector<double>& summary,
                         const std::vector<std::pair<double, std::vector<double>>>& observers) {
  // Layout: version, block(integrator: head, q, v, a), block(summary), count, (key, block(state))….
  own_.reserve(2 + observers.size());  // (no reallocation: the pieces point into them)
  std::vector<double> head = integrator.pack_head();
  const size_t state = head.size() + integrator.q.size() + integrator.v.size() + integrator.a.size();
  head.insert(head.begin(), {kVersion, static_cast<double>(state)});
  own_.push_back(std::move(head));
  pieces_.emplace_back(own_.back());
  for (const VecX* x : {&integrator.q, &integrator.v, &integrator.a})
    pieces_.emplace_back(x->data(), static_cast<size_t>(x->size()));
  std::vector<double> mid;
  put_block(mid, summary);
  mid.push_back(static_cast<double>(observers.size()));
  own_.push_back(std::move(mid));
  pieces_.emplace_back(own_.back());
  for (const auto& [k, v] : observers) {
    own_.push_back({k, static_cast<double>(v.size())});
    pieces_.emplace_back(own_.back());
    pieces_.emplace_back(v);
  }
}

size_t PackedState::size() const {
  size_t n = 0;
  for (const auto& p : pieces_) n += p.size();
  return n;
}

std::vector<double> PackedState::joined() const {
  std::vector<double> x;
  x.reserve(size());
  for (const auto& p : pieces_) x.insert(x.end(), p.begin(), p.end());
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
