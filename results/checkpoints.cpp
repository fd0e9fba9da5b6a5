// A run's checkpoints in its results group, and a run group reopened to resume from one.
//
// Dataset `checkpoint`: 2 slots (rows) × (header + state), chunked and extendible, created with the
// group (SWMR allows no new objects while the run goes). A checkpoint is written into the older slot
// after the rows it covers are flushed, then flushed itself: a run killed at any moment leaves at
// least one intact slot (its checksum agrees) whose rows are all in the file.
#include <algorithm>
#include <cstdint>
#include <cstring>

#include "writer_impl.hpp"

namespace rfem {

namespace {

// Slot header: magic, sequence, rows, flexible rows, state length, the case's checksum and the
// slot's checksum (each two 32-bit halves: exact as doubles). Slots of rfem before the case's
// checksum (kOldMagic) have no case checksum and still resume.
constexpr double kMagic = 20261204.0, kOldMagic = 20261203.0;
constexpr int kHeader = 9, kOldHeader = 7;
constexpr size_t kSlotChunk = 8192;  // values per chunk of a slot (64 KiB)

uint64_t fnv(uint64_t h, const unsigned char* b, size_t bytes) {
  for (size_t i = 0; i < bytes; ++i) h = (h ^ b[i]) * 1099511628211ull;
  return h;
}
constexpr uint64_t kFnvStart = 1469598103934665603ull;

// FNV-1a over the header's values before the slot checksum (`head` of them) and the state, as bytes.
uint64_t checksum(const double* header, int head, const double* state, size_t n) {
  const uint64_t h = fnv(kFnvStart, reinterpret_cast<const unsigned char*>(header), head * sizeof(double));
  return fnv(h, reinterpret_cast<const unsigned char*>(state), n * sizeof(double));
}

double hi(uint64_t v) { return static_cast<double>(v >> 32); }
double lo(uint64_t v) { return static_cast<double>(v & 0xffffffffull); }

}  // namespace

uint64_t writer_detail::case_checksum(const std::string& case_text, const std::string& overrides, long n_option) {
  uint64_t h = kFnvStart;
  for (const std::string& part : {case_text, overrides, std::to_string(n_option)}) {
    h = fnv(h, reinterpret_cast<const unsigned char*>(part.data()), part.size());
    h = fnv(h, reinterpret_cast<const unsigned char*>("\0"), 1);  // (parts end: "ab"+"c" is not "a"+"bc")
  }
  return h;
}

uint64_t writer_detail::case_checksum(hid_t file, const std::string& what) {
  std::string text, overrides;
  h5::read_string_attribute(file, "case_text", text);
  h5::read_string_attribute(file, "overrides", overrides);
  long n = -1;
  if (H5Aexists(file, "n_option") > 0) {
    const h5::Handle a = h5::attribute(H5Aopen(file, "n_option", H5P_DEFAULT), what);
    h5::check(H5Aread(a, H5T_NATIVE_LONG, &n), what);
  }
  return case_checksum(text, overrides, n);
}

namespace {
// A slot is written whole, but HDF5 reads the chunks a row only partly fills first: without checking
// their Fletcher-32 sums, so a damaged (torn) slot can be written over.
h5::Handle overwrite_list(const std::string& what) {
  h5::Handle dxpl = h5::plist(H5Pcreate(H5P_DATASET_XFER), what);
  h5::check(H5Pset_edc_check(dxpl, H5Z_DISABLE_EDC), what);
  return dxpl;
}

// No chunk cache: a slot is written once, chunk by chunk, and HDF5's default cache (1 MiB) would hold
// its chunks for the rest of the run (0.1 kB per rfe at 10⁴ rfes).
h5::Handle uncached(const std::string& what) {
  h5::Handle dapl = h5::plist(H5Pcreate(H5P_DATASET_ACCESS), what);
  h5::check(H5Pset_chunk_cache(dapl, 0, 0, H5D_CHUNK_CACHE_W0_DEFAULT), what);
  return dapl;
}

}  // namespace

void RunWriter::Impl::create_checkpoints() {
  const std::string w = what("creating the checkpoints of");
  const hsize_t dims[2] = {2, 0}, maxd[2] = {2, H5S_UNLIMITED}, chunk[2] = {1, kSlotChunk};
  const h5::Handle space = h5::space(H5Screate_simple(2, dims, maxd), w);
  const h5::Handle plist = h5::plist(H5Pcreate(H5P_DATASET_CREATE), w);
  h5::check(H5Pset_chunk(plist, 2, chunk), w);
  h5::checksummed(plist, w);
  checkpoints = h5::dataset(H5Dcreate2(group, "checkpoint", H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, plist, H5P_DEFAULT), w);
  h5::write_attribute(checkpoints, "description",
                      std::string("the run's state to resume from (rfem run --resume): two slots written in turn, "
                                  "each [magic, sequence, rows, flexible rows, length, case checksum (2), checksum (2), state…]"));
}

void RunWriter::checkpoint(const std::vector<std::span<const double>>& pieces) {
  const h5::Quiet quiet;
  Impl& w = *impl_;
  if (!w.group.valid() || !w.checkpoints.valid()) throw std::logic_error("RunWriter::checkpoint after finish");
  const std::string what = w.what("writing a checkpoint of");
  size_t n = 0;
  for (const auto& p : pieces) n += p.size();
  double header[kHeader];
  header[0] = kMagic;
  header[1] = static_cast<double>(++w.checkpoint_sequence);
  header[2] = static_cast<double>(w.rows);
  header[3] = static_cast<double>(w.flex_rows);
  header[4] = static_cast<double>(n);
  header[5] = hi(w.file->case_sum);
  header[6] = lo(w.file->case_sum);
  uint64_t sum = fnv(kFnvStart, reinterpret_cast<const unsigned char*>(header), 7 * sizeof(double));
  for (const auto& p : pieces) sum = fnv(sum, reinterpret_cast<const unsigned char*>(p.data()), p.size() * sizeof(double));
  header[7] = hi(sum);
  header[8] = lo(sum);
  const size_t width = kHeader + n;
  w.file->require(kMargin + w.unflushed + 2 * static_cast<long long>(width * sizeof(double)));
  w.flush();  // the rows first: the checkpoint may only cover rows that are in the file
  // Reopened without a chunk cache before every slot (SWMR's start reopens a file's datasets with the
  // default cache, whatever they were opened with).
  w.checkpoints = h5::Handle();
  w.checkpoints = h5::dataset(H5Dopen2(w.group, "checkpoint", uncached(what)), what);
  const h5::Handle old = h5::space(H5Dget_space(w.checkpoints), what);
  hsize_t dims[2] = {0, 0};
  h5::check(H5Sget_simple_extent_dims(old, dims, nullptr), what);
  if (dims[1] < width) {
    const hsize_t size[2] = {2, width};
    h5::check(H5Dset_extent(w.checkpoints, size), what);
  }
  // The slot's header and pieces gathered chunk by chunk (64 KiB): every chunk is written once, whole,
  // as a SWMR reader expects (a chunk written again in place could be read half old, half new).
  const h5::Handle fspace = h5::space(H5Dget_space(w.checkpoints), what);
  const h5::Handle dxpl = overwrite_list(what);
  const hsize_t row = static_cast<hsize_t>(w.checkpoint_sequence % 2);
  std::vector<double> chunk;
  chunk.reserve(kSlotChunk);
  hsize_t at = 0;  // the column of chunk[0]
  auto write_chunk = [&] {
    const hsize_t start[2] = {row, at}, cnt[2] = {1, chunk.size()};
    h5::check(H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, nullptr, cnt, nullptr), what);
    const h5::Handle mspace = h5::space(H5Screate_simple(2, cnt, nullptr), what);
    h5::check(H5Dwrite(w.checkpoints, H5T_NATIVE_DOUBLE, mspace, fspace, dxpl, chunk.data()), what);
    at += chunk.size();
    chunk.clear();
  };
  auto put = [&](const double* data, size_t count) {
    while (count > 0) {
      const size_t part = std::min(count, kSlotChunk - chunk.size());
      chunk.insert(chunk.end(), data, data + part);
      data += part;
      count -= part;
      if (chunk.size() == kSlotChunk) write_chunk();
    }
  };
  put(header, kHeader);
  for (const auto& p : pieces) put(p.data(), p.size());
  if (!chunk.empty()) write_chunk();
  if (w.file->swmr) h5::check(H5Dflush(w.checkpoints), what);
  w.file->flush();
}

std::optional<Checkpoint> read_checkpoint(const ResultsReader& in, const std::string& run) {
  const std::string object = run + "/checkpoint";
  if (!in.has(object)) return std::nullopt;
  const long slots = in.shape(object).first;
  const uint64_t case_sum = writer_detail::case_checksum(in.attribute("/", "case_text"), in.attribute("/", "overrides"),
                                                         static_cast<long>(in.number("/", "n_option", -1)));
  const std::string where = in.path() + ": " + run + ": ";
  std::optional<Checkpoint> best;
  bool written = false;
  for (long r = 0; r < slots; ++r) {
    Table t;
    try {
      t = in.rows(object, r, 1);  // a slot by itself: a damaged one (its Fletcher-32 checksum) leaves the other
    } catch (const ResultsError&) {
      written = true;
      continue;
    }
    const double* slot = t.data.data();
    if (std::any_of(slot, slot + t.cols, [](double x) { return x != 0; })) written = true;
    const bool old = t.cols >= kOldHeader && slot[0] == kOldMagic;
    const int header = old ? kOldHeader : kHeader;
    if (t.cols < header || (slot[0] != kMagic && !old)) continue;
    const double length = slot[4];
    if (!(length >= 0 && length <= t.cols - header)) continue;
    const size_t n = static_cast<size_t>(length);
    const uint64_t sum = checksum(slot, header - 2, slot + header, n);
    if (slot[header - 2] != hi(sum) || slot[header - 1] != lo(sum)) continue;
    if (!old && (slot[5] != hi(case_sum) || slot[6] != lo(case_sum)))
      throw ResultsError(where + "its checkpoint is of another case, other --set values or another n than the file's "
                                 "rows: not resumed (run the case again)");
    Checkpoint c;
    c.sequence = static_cast<long>(slot[1]);
    c.rows = static_cast<long>(slot[2]);
    c.flexible_rows = static_cast<long>(slot[3]);
    if (best && best->sequence > c.sequence) continue;
    c.state.assign(slot + header, slot + header + n);
    best = std::move(c);
  }
  // A run killed before its first checkpoint starts again; one whose checkpoints are all damaged
  // would lose its rows that way: refused.
  if (!best && written)
    throw ResultsError(where + "no intact checkpoint (damaged, or not this file's): not resumed (run the case again)");
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
  if (w.sensors_info) {  // (a file of an rfem that wrote the sensors only at a run's end has none: refused)
    if (H5Lexists(w.group, "sensors", H5P_DEFAULT) <= 0)
      throw ResultsError(w.what("no sensors table to resume in") + " (written by an older rfem): run the case again");
    w.measured.push_back(reopen(*w.sensors_info, from.rows));
  }
  w.rows = from.rows;
  w.flex_rows = from.flexible_rows;
  w.status = h5::dataset(H5Dopen2(w.group, "status_now", H5P_DEFAULT), w.what("reopening the status of"));
  w.checkpoints = h5::dataset(H5Dopen2(w.group, "checkpoint", H5P_DEFAULT), w.what("reopening the checkpoints of"));
  w.checkpoint_sequence = from.sequence;
  {  // The other slot is older, or newer and damaged (it was not chosen): cleared, so the file reads whole.
    const std::string what = w.what("clearing the unused checkpoint of");
    const h5::Handle fspace = h5::space(H5Dget_space(w.checkpoints), what);
    hsize_t dims[2] = {0, 0};
    h5::check(H5Sget_simple_extent_dims(fspace, dims, nullptr), what);
    if (dims[0] == 2 && dims[1] > 0) {
      const std::vector<double> zero(dims[1], 0.0);
      const hsize_t start[2] = {static_cast<hsize_t>((from.sequence + 1) % 2), 0}, count[2] = {1, dims[1]};
      h5::check(H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, nullptr, count, nullptr), what);
      const h5::Handle mspace = h5::space(H5Screate_simple(2, count, nullptr), what);
      h5::check(H5Dwrite(w.checkpoints, H5T_NATIVE_DOUBLE, mspace, fspace, overwrite_list(what), zero.data()), what);
    }
  }
  h5::write_attribute(w.group, "status", std::string("running"));
  w.set_status("running");
  writer_detail::queue_run_description(f, name, d);
  f.pending.push_back({name, "resumed_from_row", from.rows});  // (the output row the run went on from)
  f.begin_swmr();
  w.last_flush = now_s();
  return std::make_unique<RunWriter>(std::move(p));
}

}  // namespace rfem
