// A run's checkpoints in its results group, and a run group reopened to resume from one.
//
// Dataset `checkpoint`: 2 slots (rows) × (header + state), chunked and extendible, created with the
// group (SWMR allows no new objects while the run goes). A checkpoint is written into the older slot
// after the rows it covers are flushed, then flushed itself: a run killed at any moment leaves at
// least one intact slot (its checksum agrees) whose rows are all in the file.
#include <cstdint>
#include <cstring>

#include "rfem/results/writer_impl.hpp"

namespace rfem {

namespace {

// Slot header: magic, sequence, rows, flexible rows, state length, checksum (two 32-bit halves).
constexpr double kMagic = 20261203.0;
constexpr int kHeader = 7;

// FNV-1a over the header's first five values and the state, as bytes.
uint64_t checksum(const double* header, const double* state, size_t n) {
  uint64_t h = 1469598103934665603ull;
  auto eat = [&](const double* p, size_t count) {
    const auto* b = reinterpret_cast<const unsigned char*>(p);
    for (size_t i = 0; i < count * sizeof(double); ++i) h = (h ^ b[i]) * 1099511628211ull;
  };
  eat(header, 5);
  eat(state, n);
  return h;
}

}  // namespace

void RunWriter::Impl::create_checkpoints() {
  const std::string w = what("creating the checkpoints of");
  const hsize_t dims[2] = {2, 0}, maxd[2] = {2, H5S_UNLIMITED}, chunk[2] = {1, 8192};
  const h5::Handle space = h5::space(H5Screate_simple(2, dims, maxd), w);
  const h5::Handle plist = h5::plist(H5Pcreate(H5P_DATASET_CREATE), w);
  h5::check(H5Pset_chunk(plist, 2, chunk), w);
  checkpoints = h5::dataset(H5Dcreate2(group, "checkpoint", H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, plist, H5P_DEFAULT), w);
  h5::write_attribute(checkpoints, "description",
                      std::string("the run's state to resume from (rfem run --resume): two slots written in turn, "
                                  "each [magic, sequence, rows, flexible rows, length, checksum, checksum, state…]"));
}

void RunWriter::checkpoint(const std::vector<double>& state) {
  const h5::Quiet quiet;
  Impl& w = *impl_;
  if (!w.group.valid() || !w.checkpoints.valid()) throw std::logic_error("RunWriter::checkpoint after finish");
  const std::string what = w.what("writing a checkpoint of");
  std::vector<double> slot(kHeader + state.size());
  slot[0] = kMagic;
  slot[1] = static_cast<double>(++w.checkpoint_sequence);
  slot[2] = static_cast<double>(w.rows);
  slot[3] = static_cast<double>(w.flex_rows);
  slot[4] = static_cast<double>(state.size());
  const uint64_t sum = checksum(slot.data(), state.data(), state.size());
  slot[5] = static_cast<double>(sum >> 32);
  slot[6] = static_cast<double>(sum & 0xffffffffull);
  std::copy(state.begin(), state.end(), slot.begin() + kHeader);
  w.file->require(kMargin + w.unflushed + 2 * static_cast<long long>(slot.size() * sizeof(double)));
  w.flush();  // the rows first: the checkpoint may only cover rows that are in the file
  const h5::Handle old = h5::space(H5Dget_space(w.checkpoints), what);
  hsize_t dims[2] = {0, 0};
  h5::check(H5Sget_simple_extent_dims(old, dims, nullptr), what);
  if (dims[1] < slot.size()) {
    const hsize_t size[2] = {2, slot.size()};
    h5::check(H5Dset_extent(w.checkpoints, size), what);
  }
  const h5::Handle fspace = h5::space(H5Dget_space(w.checkpoints), what);
  const hsize_t start[2] = {static_cast<hsize_t>(w.checkpoint_sequence % 2), 0}, count[2] = {1, slot.size()};
  h5::check(H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, nullptr, count, nullptr), what);
  const h5::Handle mspace = h5::space(H5Screate_simple(2, count, nullptr), what);
  h5::check(H5Dwrite(w.checkpoints, H5T_NATIVE_DOUBLE, mspace, fspace, H5P_DEFAULT, slot.data()), what);
  if (w.file->swmr) h5::check(H5Dflush(w.checkpoints), what);
  w.file->flush();
}

std::optional<Checkpoint> read_checkpoint(const ResultsReader& in, const std::string& run) {
  const std::string object = run + "/checkpoint";
  if (!in.has(object)) return std::nullopt;
  const Table t = in.table(object);
  std::optional<Checkpoint> best;
  for (long r = 0; r < t.rows; ++r) {
    if (t.cols < kHeader) break;
    const double* slot = t.data.data() + r * t.cols;
    const double length = slot[4];
    if (slot[0] != kMagic || !(length >= 0 && length <= t.cols - kHeader)) continue;
    const size_t n = static_cast<size_t>(length);
    const uint64_t sum = checksum(slot, slot + kHeader, n);
    if (slot[5] != static_cast<double>(sum >> 32) || slot[6] != static_cast<double>(sum & 0xffffffffull)) continue;
    Checkpoint c;
    c.sequence = static_cast<long>(slot[1]);
    c.rows = static_cast<long>(slot[2]);
    c.flexible_rows = static_cast<long>(slot[3]);
    if (best && best->sequence > c.sequence) continue;
    c.state.assign(slot + kHeader, slot + kHeader + n);
    best = std::move(c);
  }
  return best;
}

std::unique_ptr<RunWriter> ResultsWriter::resume_run(const std::string& name, std::shared_ptr<const Model> model,
                                                    const RunDescription& d, const Checkpoint& from) {
  if (!model) throw std::invalid_argument("ResultsWriter::resume_run: no model");
  const h5::Quiet quiet;
  File& f = *file_;
  f.end_swmr();
  f.require(2 * kMargin);
  auto p = RunWriter::Impl::make(file_, name, model, d);
  RunWriter::Impl& w = *p;
  w.group = h5::group(H5Gopen2(f.id, name.c_str(), H5P_DEFAULT), f.what("no run group " + name + " to resume in"));
  // The series cut back to the rows the checkpoint covers (what came after it is computed again).
  auto reopen = [&](const SeriesInfo& info, long rows) {
    const std::string what = w.what("reopening " + info.name + " of");
    RunWriter::Impl::Series s;
    s.dset = h5::dataset(H5Dopen2(w.group, info.name.c_str(), H5P_DEFAULT), what);
    const h5::Handle space = h5::space(H5Dget_space(s.dset), what);
    hsize_t dims[2] = {0, 0};
    if (H5Sget_simple_extent_ndims(space) != 2) throw ResultsError(what + ": not a series of this run");
    h5::check(H5Sget_simple_extent_dims(space, dims, nullptr), what);
    if (dims[1] != static_cast<hsize_t>(info.width()) || dims[0] < static_cast<hsize_t>(rows))
      throw ResultsError(what + ": its shape does not fit the checkpoint (another model?)");
    const hsize_t size[2] = {static_cast<hsize_t>(rows), dims[1]};
    h5::check(H5Dset_extent(s.dset, size), what);
    const h5::Handle plist = h5::plist(H5Dget_create_plist(s.dset), what);
    hsize_t chunk[2] = {1, 1};
    h5::check(H5Pget_chunk(plist, 2, chunk), what);
    s.cols = info.width();
    s.chunk_rows = static_cast<long>(chunk[0]);
    s.name = info.name;
    return s;
  };
  for (const SeriesInfo& s : w.layout.series) w.series.push_back(reopen(s, from.rows));
  for (const SeriesInfo& s : w.layout.flexible) w.flexible.push_back(reopen(s, from.flexible_rows));
  w.rows = from.rows;
  w.flex_rows = from.flexible_rows;
  w.status = h5::dataset(H5Dopen2(w.group, "status_now", H5P_DEFAULT), w.what("reopening the status of"));
  w.checkpoints = h5::dataset(H5Dopen2(w.group, "checkpoint", H5P_DEFAULT), w.what("reopening the checkpoints of"));
  w.checkpoint_sequence = from.sequence;
  h5::write_attribute(w.group, "status", std::string("running"));
  w.set_status("running");
  writer_detail::queue_run_description(f, name, d);
  f.pending.push_back({name, "resumed_from_row", from.rows});  // (the output row the run went on from)
  f.begin_swmr();
  w.last_flush = now_s();
  return std::make_unique<RunWriter>(std::move(p));
}

}  // namespace rfem
