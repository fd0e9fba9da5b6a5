#include "state.hpp"

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "../core/model.hpp"
#include "../results/reader.hpp"
#include "../results/writer.hpp"
#include "inputs.hpp"

namespace rfem {

namespace {

constexpr double kStateVersion = 3.0;  // (1: no memory of the laws, 2: no sensors' noise; still read)
// A checkpoint's layout: 1 held the integrator's state alone (the laws' memory and the sensors'
// streams among the observers' states; still read), 2 a SimulationState.
constexpr double kCheckpointVersion = 2.0;
constexpr const char* kLawsKey = "joint laws";  // (layout 1's key of the laws' memory)

double key_hash(const std::string& key) {  // FNV-1a, 32 bits: exact as a double
  uint32_t h = 2166136261u;
  for (unsigned char c : key) h = (h ^ c) * 16777619u;
  return static_cast<double>(h);
}

}  // namespace

std::vector<std::span<const double>> SimulationState::pieces(std::vector<std::vector<double>>& own) const {
  // Layout: version, drives' count and values, laws' count and values, the integrator's head, q, v,
  // a, sensors' count and values (after the integrator: its length is in its head).
  std::vector<double> head = {kStateVersion, static_cast<double>(drives.size())};
  head.insert(head.end(), drives.begin(), drives.end());
  head.push_back(static_cast<double>(laws.size()));
  head.insert(head.end(), laws.begin(), laws.end());
  const std::vector<double> i = integrator.pack_head();
  head.insert(head.end(), i.begin(), i.end());
  std::vector<double> tail = {static_cast<double>(sensors.size())};
  tail.insert(tail.end(), sensors.begin(), sensors.end());
  own.push_back(std::move(head));  // (a moved vector keeps its values where they were)
  std::vector<std::span<const double>> p = {own.back()};
  for (const VecX* x : {&integrator.q, &integrator.v, &integrator.a}) p.emplace_back(x->data(), static_cast<size_t>(x->size()));
  own.push_back(std::move(tail));
  p.emplace_back(own.back());
  return p;
}

std::vector<double> SimulationState::pack() const {
  std::vector<std::vector<double>> own;
  std::vector<double> x;
  for (const auto& p : pieces(own)) x.insert(x.end(), p.begin(), p.end());
  return x;
}

SimulationState SimulationState::unpack(const std::string& model, const std::vector<double>& x) {
  const auto bad = [] { return std::invalid_argument("not a simulation state of this version of rfem"); };
  // A count at x[i]: a whole number with that many values after it.
  const auto count = [&](size_t i) {
    if (i >= x.size() || !(x[i] >= 0) || x[i] != std::floor(x[i]) || x[i] > static_cast<double>(x.size() - i - 1)) throw bad();
    return static_cast<size_t>(x[i]);
  };
  if (x.size() < 2 || (x[0] != kStateVersion && x[0] != 2.0 && x[0] != 1.0)) throw bad();
  SimulationState s;
  s.model = model;
  const size_t nd = count(1);
  s.drives.assign(x.begin() + 2, x.begin() + 2 + static_cast<long>(nd));
  size_t i = 2 + nd;
  const auto block = [&](std::vector<double>& to) {
    const size_t k = count(i++);
    to.assign(x.begin() + static_cast<long>(i), x.begin() + static_cast<long>(i + k));
    i += k;
  };
  if (x[0] >= 2.0) block(s.laws);
  size_t end = x.size();
  if (x[0] >= 3.0) {  // the integrator's state (its head, then q, v, a), then the sensors' block
    const size_t head = IntegratorState{}.pack_head().size();
    if (i + head > x.size()) throw bad();
    const double u = x[i + head - 1];
    if (!(u >= 0 && u == std::floor(u) && u <= static_cast<double>(x.size()))) throw bad();
    end = i + head + 3 * static_cast<size_t>(u);
    if (end >= x.size()) throw std::invalid_argument("the state of " + std::to_string(static_cast<long>(u)) + " unknowns is cut short");
    size_t j = end;
    std::swap(i, j);
    block(s.sensors);
    std::swap(i, j);
    if (j != x.size()) throw std::invalid_argument("the state has values after its end: not a state of this version of rfem");
  }
  for (double d : s.drives)
    if (!std::isfinite(d)) throw std::invalid_argument("the state's held drive values are not finite");
  for (double d : s.laws)  // (a digital law that has not sampled yet remembers its last sample at −inf)
    if (std::isnan(d)) throw std::invalid_argument("the state's memory of the joints' laws holds NaN");
  s.integrator = IntegratorState::unpack(std::vector<double>(x.begin() + static_cast<long>(i), x.begin() + static_cast<long>(end)), -1);
  return s;
}

std::string model_signature(const Model& model, const std::vector<JointInput>& inputs) {
  std::string s = "n=" + std::to_string(model.n()) + "; links=";
  for (size_t l = 0; l < model.links.size(); ++l) {  // (a reduced link's state is over its own basis)
    const Discretisation& d = model.links[l].d;
    s += (l ? "," : "") + model.links[l].name + ":" + std::to_string(model.links[l].n());
    if (d.modes > 0) s += ":modes=" + std::to_string(d.modes) + ":derivatives=" + std::to_string(d.derivatives);
  }
  s += "; joints=";
  const std::vector<std::string> kinds = input_kinds(inputs);
  for (int j = 0; j < model.m(); ++j)
    s += (j ? "," : "") + model.joints[j].name + ":" + (model.joints[j].type == JointType::Revolute ? "revolute" : "prismatic") +
         ":" + kinds[j];
  return s;
}

void save_state(const SimulationState& state, const std::string& path) {
  FileDescription d;
  d.command_line = "rfem simulation state at t = " + std::to_string(state.time()) + " s";
  d.procedure = "state";
  ResultsWriter w(path, d);
  const std::vector<double> x = state.pack();
  w.write_table("state/packed", Table{static_cast<long>(x.size()), 1, x}, {"value"}, {""},
                "a simulation's state (simulation/state.hpp: SimulationState::pack)");
  w.write_attribute("state", "model", state.model);
  w.close();
}

SimulationState load_state(const std::string& path) {
  const ResultsReader in(path);
  const std::string model = in.attribute("state", "model");
  if (model.empty()) throw std::invalid_argument(path + ": no simulation state in it (state/model)");
  try {
    return SimulationState::unpack(model, in.table("state/packed").data);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(path + ": " + e.what());
  }
}


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

PackedState::PackedState(const SimulationState& state, const std::vector<double>& summary,
                         const std::vector<std::pair<double, std::vector<double>>>& observers) {
  // Layout: version, block(the simulation's state), block(summary), count, (key, block(state))….
  own_.reserve(5 + observers.size());
  own_.push_back({kCheckpointVersion, 0.0});
  pieces_.emplace_back(own_.back());
  size_t length = 0;
  for (const auto& p : state.pieces(own_)) {
    pieces_.push_back(p);
    length += p.size();
  }
  own_.front()[1] = static_cast<double>(length);
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

RunState RunState::unpack(const std::vector<double>& x) {
  size_t i = 0;
  const std::string why = "the checkpoint is damaged or from another version of rfem";
  auto bad = [&] { return std::invalid_argument(why); };
  auto block = [&] { return take_block(x, i, why); };
  if (x.empty() || (x[0] != kCheckpointVersion && x[0] != 1.0)) throw bad();
  const bool layout1 = x[0] == 1.0;
  i = 1;
  RunState s;
  try {
    if (layout1) s.state.integrator = IntegratorState::unpack(block(), -1);
    else s.state = SimulationState::unpack("", block());
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("the checkpoint's state: " + std::string(e.what()));
  }
  s.summary = block();
  if (i >= x.size()) throw bad();
  const double count = x[i++];
  for (double k = 0; k < count; ++k) {
    if (i >= x.size()) throw bad();
    const double key = x[i++];
    s.observers.emplace_back(key, block());
  }
  if (i != x.size()) throw bad();
  // (Layout 1's sensors' streams were taken after the row at the state's time: not this layout's,
  // so left out: a run with sensors refuses such a checkpoint.)
  if (layout1)
    if (const std::vector<double>* laws = s.find(kLawsKey)) s.state.laws = *laws;
  return s;
}

}  // namespace rfem
