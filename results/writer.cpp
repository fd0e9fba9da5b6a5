#include "rfem/results/writer.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <variant>

#include "rfem/results/h5_impl.hpp"
#include "rfem/version.hpp"

namespace rfem {

namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

h5::Handle latest_fapl() {  // SWMR needs the latest file format
  h5::Handle fapl = h5::plist(H5Pcreate(H5P_FILE_ACCESS), "file access list");
  h5::check(H5Pset_libver_bounds(fapl, H5F_LIBVER_LATEST, H5F_LIBVER_LATEST), "file access list");
  return fapl;
}

}  // namespace

// Room a run's group needs besides its chunks of rows: metadata flushes, the attributes written at
// its end, closing the file (measured: a run group's metadata takes 20–40 kB).
constexpr long long kMargin = 64 * 1024;

struct ResultsWriter::File {
  std::string path;
  h5::Handle id;
  int lock_fd = -1;  // holds the open-file-description lock that keeps other rfem writers out
  bool swmr = false;
  using Value = std::variant<std::string, double, long>;
  struct Pending {
    std::string object, key;
    Value value;
  };
  std::vector<Pending> pending;  // attributes that wait for the end of SWMR mode

  std::string what(const std::string& doing) const { return path + ": " + doing; }

  ~File() {
    if (lock_fd >= 0) ::close(lock_fd);
  }

  // Refuses (ResultsError) a write of `bytes` more that the disk or the file size limit (ulimit -f)
  // cannot take. HDF5 cannot recover from a failed write (its file is left unreadable, and its own
  // clean-up at exit crashes), so writes stop while there is still room to record why.
  void require(long long bytes) const {
    const std::string dir = std::filesystem::path(path).parent_path().string();
    struct statvfs fs {};
    if (statvfs(dir.empty() ? "." : dir.c_str(), &fs) == 0) {
      const long long free = static_cast<long long>(fs.f_bavail) * static_cast<long long>(fs.f_frsize);
      if (free < bytes)
        throw ResultsError("cannot write " + path + ": the disk is full (" + std::to_string(free / 1024) + " kB free, " +
                           std::to_string(bytes / 1024) + " kB needed for the next rows)");
    }
    struct rlimit rl {};
    struct stat st {};
    if (getrlimit(RLIMIT_FSIZE, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY && ::stat(path.c_str(), &st) == 0 &&
        static_cast<long long>(st.st_size) + bytes > static_cast<long long>(rl.rlim_cur))
      throw ResultsError("cannot write " + path + ": the file size limit (ulimit -f, " + std::to_string(rl.rlim_cur / 1024) +
                         " kB) is reached");
  }

  void attribute(const std::string& object, const std::string& key, const Value& value) {
    if (swmr) {
      pending.push_back({object, key, value});
      return;
    }
    const h5::Handle obj = h5::object(H5Oopen(id, object.c_str(), H5P_DEFAULT), what("opening " + object));
    try {
      std::visit([&](const auto& v) { h5::write_attribute(obj, key, v); }, value);
    } catch (const ResultsError& e) {
      throw ResultsError(what(object + " " + e.what()));
    }
  }
  void flush() { h5::check(H5Fflush(id, H5F_SCOPE_GLOBAL), what("flushing")); }
  void begin_swmr() {
    if (swmr) return;
    flush();
    swmr = H5Fstart_swmr_write(id) >= 0;  // without SWMR the run is still written, just not watchable
    h5::reason();                          // (clears the stack of a refusal)
  }
  // Leaves SWMR mode if in it, and writes the attributes that waited for that.
  void end_swmr() {
    if (swmr) {
      swmr = false;
      id.close(what("closing after SWMR writing"));
      // Readers that watched the run (SWMR, shared locks) may still have the file open: reopen
      // without file locks for the attributes and the next run's group (a watcher reopens to see them).
      const h5::Handle fapl = latest_fapl();
      h5::check(H5Pset_file_locking(fapl, false, true), what("reopening"));
      id = h5::file(H5Fopen(path.c_str(), H5F_ACC_RDWR, fapl), what("cannot reopen the results file"));
    }
    if (pending.empty()) return;
    std::vector<Pending> p;
    p.swap(pending);
    for (const auto& x : p) attribute(x.object, x.key, x.value);
    flush();
  }
};

namespace {

// What may not be overwritten: the case itself, a file that is not HDF5, a file another rfem run
// writes. Returns the descriptor that holds the lock (an open-file-description lock far beyond the
// file's data: HDF5's own locks are flock()s, which SWMR writing drops, and readers take none).
int claim(const std::string& path, const std::string& case_path) {
  std::error_code ec;
  if (!case_path.empty() && std::filesystem::exists(path, ec) && std::filesystem::equivalent(path, case_path, ec))
    throw ResultsError(path + ": is the case file: results would overwrite it (choose another -o)");
  if (std::filesystem::is_directory(path, ec)) throw ResultsError(path + ": is a directory, not a results file");
  if (std::filesystem::exists(path, ec) && std::filesystem::file_size(path, ec) > 0 && H5Fis_hdf5(path.c_str()) <= 0) {
    h5::reason();
    throw ResultsError(path + ": exists and is not an HDF5 file: not overwritten (remove it, or choose another -o)");
  }
  const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) throw ResultsError(path + ": cannot create results file (" + std::strerror(errno) + ")");
  struct flock lk {};
  lk.l_type = F_WRLCK;
  lk.l_whence = SEEK_SET;
  lk.l_start = 1LL << 62;  // a byte no HDF5 file reaches
  lk.l_len = 1;
  if (fcntl(fd, F_OFD_SETLK, &lk) != 0) {
    const int err = errno;
    ::close(fd);
    if (err == EAGAIN || err == EACCES)
      throw ResultsError(path + ": another rfem run is writing this file (choose another -o, or wait for it)");
    throw ResultsError(path + ": cannot lock the results file (" + std::strerror(err) + ")");
  }
  return fd;
}

}  // namespace

ResultsWriter::ResultsWriter(const std::string& path, const FileDescription& d) : file_(std::make_shared<File>()) {
  const h5::Quiet quiet;
  file_->path = path;
  file_->lock_fd = claim(path, d.case_path);
  file_->require(kMargin);
  const h5::Handle fapl = latest_fapl();
  file_->id = h5::file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl),
                       path + ": cannot create results file (is the directory writable?)");
  file_->attribute("/", "rfem_version", std::string(version_string));
  file_->attribute("/", "build", std::string(build_description()));
  file_->attribute("/", "command_line", d.command_line);
  file_->attribute("/", "case_path", d.case_path);
  file_->attribute("/", "case_text", d.case_text);
  file_->attribute("/", "case_effective", d.case_effective);
  file_->attribute("/", "overrides", d.overrides);
  file_->attribute("/", "procedure", d.procedure);
  if (d.n >= 0) file_->attribute("/", "n", d.n);
  file_->attribute("/", "threads", d.threads);
}

ResultsWriter::~ResultsWriter() {
  if (!file_) return;
  try {
    close();
  } catch (...) {  // a destructor does not throw; close() reports to whoever calls it
  }
}
ResultsWriter::ResultsWriter(ResultsWriter&&) noexcept = default;
ResultsWriter& ResultsWriter::operator=(ResultsWriter&&) noexcept = default;

const std::string& ResultsWriter::path() const { return file_->path; }

void ResultsWriter::close() {
  if (!file_ || !file_->id.valid()) return;
  const h5::Quiet quiet;
  file_->end_swmr();
  file_->flush();
  file_->id.close(file_->what("closing"));
}

namespace {
void put_vector(hid_t g, const char* name, const std::vector<double>& v, const std::string& what) {
  const hsize_t dims[1] = {v.size()};
  const h5::Handle sp = h5::space(H5Screate_simple(1, dims, nullptr), what);
  const h5::Handle ds = h5::dataset(H5Dcreate2(g, name, H5T_NATIVE_DOUBLE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), what);
  if (!v.empty()) h5::check(H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), what);
}
}  // namespace

void ResultsWriter::write_refinement(const std::vector<std::string>& quantities, const std::vector<int>& ns,
                                     const std::vector<Refinement>& tables, const RunStatus& status) {
  const h5::Quiet quiet;
  File& f = *file_;
  f.end_swmr();
  const std::string what = f.what("writing the refinement tables");
  if (H5Lexists(f.id, "refine", H5P_DEFAULT) > 0) h5::check(H5Ldelete(f.id, "refine", H5P_DEFAULT), what);
  const h5::Handle g = h5::group(H5Gcreate2(f.id, "refine", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), what);
  put_vector(g, "n", std::vector<double>(ns.begin(), ns.end()), what);
  h5::write_attribute(g, "status", status.to_string());
  h5::write_attribute(g, "quantities", static_cast<long>(quantities.size()));
  for (size_t k = 0; k < quantities.size(); ++k) {
    const Refinement& t = tables[k];
    const h5::Handle q = h5::group(H5Gcreate2(g, ("q" + std::to_string(k)).c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), what);
    for (hid_t where : {q.get(), k == 0 ? g.get() : hid_t(-1)}) {
      if (where < 0) continue;
      put_vector(where, "value", t.column(&RefinementRow::value), what);
      put_vector(where, "change", t.column(&RefinementRow::change), what);
      put_vector(where, "order", t.column(&RefinementRow::order), what);
      put_vector(where, "richardson", t.column(&RefinementRow::richardson), what);
      h5::write_attribute(where, "quantity", quantities[k]);
      h5::write_attribute(where, "fitted_order", t.fitted_order);
      h5::write_attribute(where, "integration_error", t.integration_error);
      std::string w;
      for (const auto& x : t.warnings) w += (w.empty() ? "" : "\n") + x;
      h5::write_attribute(where, "warnings", w);
      if (std::isfinite(t.reference())) h5::write_attribute(where, "reference", t.reference());
    }
  }
  f.flush();
}

void ResultsWriter::write_table(const std::string& name, const Table& t, const std::vector<std::string>& columns,
                                const std::vector<std::string>& units, const std::string& description) {
  const h5::Quiet quiet;
  File& f = *file_;
  f.end_swmr();
  if (static_cast<long>(t.data.size()) != t.rows * t.cols || static_cast<long>(columns.size()) != t.cols ||
      static_cast<long>(units.size()) != t.cols)
    throw std::invalid_argument("ResultsWriter::write_table: " + name + ": sizes do not agree");
  f.require(kMargin + static_cast<long long>(t.data.size() * sizeof(double)));
  const std::string what = f.what("writing " + name);
  const hsize_t dims[2] = {static_cast<hsize_t>(t.rows), static_cast<hsize_t>(t.cols)};
  const h5::Handle sp = h5::space(H5Screate_simple(2, dims, nullptr), what);
  const h5::Handle lcpl = h5::plist(H5Pcreate(H5P_LINK_CREATE), what);
  h5::check(H5Pset_create_intermediate_group(lcpl, 1), what);
  const h5::Handle ds = h5::dataset(H5Dcreate2(f.id, name.c_str(), H5T_NATIVE_DOUBLE, sp, lcpl, H5P_DEFAULT, H5P_DEFAULT), what);
  if (!t.data.empty()) h5::check(H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, t.data.data()), what);
  h5::write_attribute(ds, "columns", columns);
  h5::write_attribute(ds, "units", units);
  h5::write_attribute(ds, "description", description);
}

void ResultsWriter::write_attribute(const std::string& object, const std::string& key, const std::string& value) {
  const h5::Quiet quiet;
  file_->end_swmr();
  file_->attribute(object, key, value);
}

void ResultsWriter::write_attribute(const std::string& object, const std::string& key, const std::vector<std::string>& values) {
  const h5::Quiet quiet;
  File& f = *file_;
  f.end_swmr();
  const h5::Handle obj = h5::object(H5Oopen(f.id, object.c_str(), H5P_DEFAULT), f.what("opening " + object));
  h5::write_attribute(obj, key, values);
}

void ResultsWriter::write_external_link(const std::string& name, const std::string& file, const std::string& object) {
  const h5::Quiet quiet;
  File& f = *file_;
  f.end_swmr();
  const std::string what = f.what("linking " + name);
  const h5::Handle lcpl = h5::plist(H5Pcreate(H5P_LINK_CREATE), what);
  h5::check(H5Pset_create_intermediate_group(lcpl, 1), what);
  h5::check(H5Lcreate_external(file.c_str(), object.c_str(), f.id, name.c_str(), lcpl, H5P_DEFAULT), what);
}

// ---------------------------------------------------------------------------------------------

struct RunWriter::Impl {
  std::shared_ptr<ResultsWriter::File> file;
  std::string name;
  std::shared_ptr<const Model> model;
  RunLayout layout;
  struct Series {
    h5::Handle dset;
    int cols = 1;
    long chunk_rows = 1;
    std::string name;
  };
  std::vector<Series> series, flexible;
  h5::Handle group, status;
  long rows = 0, flex_rows = 0;
  double last_flush = 0.0;
  long long unflushed = 0;  // bytes of chunks started since the last flush
  std::vector<std::vector<double>> scratch;

  // File space the rows `row` of these series will allocate: a new chunk for each that starts one.
  static long long new_chunks(const std::vector<Series>& v, long row) {
    long long bytes = 0;
    for (const Series& s : v)
      if (row % s.chunk_rows == 0) bytes += static_cast<long long>(s.chunk_rows) * s.cols * static_cast<long long>(sizeof(double));
    return bytes;
  }

  std::string what(const std::string& doing) const { return file->what(doing + " " + name); }

  Series add_series(const SeriesInfo& info) {
    const std::string w = what("creating " + info.name + " in");
    const hsize_t dims[2] = {0, static_cast<hsize_t>(info.width())};
    const hsize_t maxd[2] = {H5S_UNLIMITED, dims[1]};
    const h5::Handle space = h5::space(H5Screate_simple(2, dims, maxd), w);
    const h5::Handle plist = h5::plist(H5Pcreate(H5P_DATASET_CREATE), w);
    const hsize_t chunk[2] = {std::max<hsize_t>(1, std::min<hsize_t>(256, (1 << 16) / dims[1])), dims[1]};
    h5::check(H5Pset_chunk(plist, 2, chunk), w);
    const h5::Handle lcpl = h5::plist(H5Pcreate(H5P_LINK_CREATE), w);  // "links/NAME/tip" creates its groups
    h5::check(H5Pset_create_intermediate_group(lcpl, 1), w);
    Series s;
    s.dset = h5::dataset(H5Dcreate2(group, info.name.c_str(), H5T_NATIVE_DOUBLE, space, lcpl, plist, H5P_DEFAULT), w);
    h5::write_attribute(s.dset, "columns", info.columns);
    h5::write_attribute(s.dset, "units", info.units);
    if (!info.description.empty()) h5::write_attribute(s.dset, "description", info.description);
    s.cols = info.width();
    s.chunk_rows = static_cast<long>(chunk[0]);
    s.name = info.name;
    return s;
  }

  void write_row(Series& s, long row, const double* data) {
    const std::string w = what("writing " + s.name + " of");
    const hsize_t size[2] = {static_cast<hsize_t>(row + 1), static_cast<hsize_t>(s.cols)};
    h5::check(H5Dset_extent(s.dset, size), w);
    const h5::Handle fspace = h5::space(H5Dget_space(s.dset), w);
    const hsize_t start[2] = {static_cast<hsize_t>(row), 0}, count[2] = {1, static_cast<hsize_t>(s.cols)};
    h5::check(H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, nullptr, count, nullptr), w);
    const h5::Handle mspace = h5::space(H5Screate_simple(2, count, nullptr), w);
    h5::check(H5Dwrite(s.dset, H5T_NATIVE_DOUBLE, mspace, fspace, H5P_DEFAULT, data), w);
  }

  void set_status(const std::string& text) {
    if (!status.valid()) return;
    const h5::Handle type = h5::type(H5Tcopy(H5T_C_S1), what("status of"));
    h5::check(H5Tset_size(type, 256), what("status of"));
    char buf[256] = {0};
    text.copy(buf, 255);
    h5::check(H5Dwrite(status, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf), what("writing the status of"));
  }

  void flush() {
    if (!group.valid()) return;
    if (file->swmr) {
      for (auto* v : {&series, &flexible})
        for (auto& s : *v) h5::check(H5Dflush(s.dset), what("flushing " + s.name + " of"));
      if (status.valid()) h5::check(H5Dflush(status), what("flushing the status of"));
    }
    file->flush();
    last_flush = now_s();
    unflushed = 0;
  }

  // Closes the datasets and the group (before the file leaves SWMR mode); never throws.
  void close_quietly() {
    for (auto* v : {&series, &flexible})
      for (auto& s : *v) s.dset.reset();
    status.reset();
    group.reset();
  }
};

RunWriter::RunWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

RunWriter::~RunWriter() {
  if (!impl_) return;
  const h5::Quiet quiet;
  try {
    impl_->flush();
  } catch (...) {  // (a destructor does not throw: what failed was reported by append or finish)
  }
  impl_->close_quietly();
}

long RunWriter::samples() const { return impl_->rows; }

std::unique_ptr<RunWriter> ResultsWriter::begin_run(const std::string& name, std::shared_ptr<const Model> model,
                                                   const RunDescription& d) {
  if (!model) throw std::invalid_argument("ResultsWriter::begin_run: no model");
  const h5::Quiet quiet;
  File& f = *file_;
  f.end_swmr();  // a new group: not while another run's SWMR lasts
  f.require(2 * kMargin);
  auto p = std::make_unique<RunWriter::Impl>();
  RunWriter::Impl& w = *p;
  w.file = file_;
  w.name = name;
  w.model = model;
  w.layout = run_layout(*model, d.flexible_every);
  const Model& M = *model;
  const h5::Handle lcpl = h5::plist(H5Pcreate(H5P_LINK_CREATE), f.what("creating group " + name));
  h5::check(H5Pset_create_intermediate_group(lcpl, 1), f.what("creating group " + name));  // "n60/kinematic"
  w.group = h5::group(H5Gcreate2(f.id, name.c_str(), lcpl, H5P_DEFAULT, H5P_DEFAULT), f.what("cannot create group " + name));
  for (const SeriesInfo& s : w.layout.series) w.series.push_back(w.add_series(s));
  for (const SeriesInfo& s : w.layout.flexible) w.flexible.push_back(w.add_series(s));
  for (const auto& [info, values] : w.layout.constants) {
    const std::string what = w.what("creating " + info.name + " in");
    const hsize_t dims[2] = {values.size() / info.width(), static_cast<hsize_t>(info.width())};
    const h5::Handle sp = h5::space(H5Screate_simple(2, dims, nullptr), what);
    const h5::Handle ds =
        h5::dataset(H5Dcreate2(w.group, info.name.c_str(), H5T_NATIVE_DOUBLE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), what);
    h5::check(H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), what);
    h5::write_attribute(ds, "columns", info.columns);
    h5::write_attribute(ds, "units", info.units);
    h5::write_attribute(ds, "description", info.description);
  }
  for (const auto& [alias, target] : w.layout.aliases)
    h5::check(H5Lcreate_soft(target.c_str(), w.group, alias.c_str(), H5P_DEFAULT, H5P_DEFAULT), w.what("linking " + alias + " in"));
  {  // the live status: a fixed-size string, writable while the file is in SWMR mode
    const h5::Handle type = h5::type(H5Tcopy(H5T_C_S1), w.what("status of"));
    h5::check(H5Tset_size(type, 256), w.what("status of"));
    const h5::Handle sp = h5::space(H5Screate(H5S_SCALAR), w.what("status of"));
    w.status = h5::dataset(H5Dcreate2(w.group, "status_now", type, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), w.what("status of"));
  }
  std::vector<std::string> jn, jt, ju, link_names;
  for (const auto& j : M.joints) {
    const bool rev = j.type == JointType::Revolute;
    jn.push_back(j.name);
    jt.push_back(rev ? "revolute" : "prismatic");
    ju.push_back(rev ? "rad" : "m");
  }
  for (const MountedLink& L : M.links) link_names.push_back(L.name);
  h5::write_attribute(w.group, "n", static_cast<long>(M.n()));
  h5::write_attribute(w.group, "m", static_cast<long>(M.m()));
  h5::write_attribute(w.group, "joint_names", jn);
  h5::write_attribute(w.group, "joint_types", jt);
  h5::write_attribute(w.group, "joint_units", ju);
  if (!link_names.empty()) h5::write_attribute(w.group, "link_names", link_names);
  h5::write_attribute(w.group, "status", std::string("running"));
  w.set_status("running");
  // What the run is, written at its end (SWMR allows no new attributes while it goes).
  const IntegratorOptions& o = d.options;
  f.pending.push_back({name, "rtol", o.rtol});
  f.pending.push_back({name, "atol", o.atol});
  f.pending.push_back({name, "atol_velocity", o.atol_velocity});
  f.pending.push_back({name, "max_step", o.max_step});
  f.pending.push_back({name, "integrator", integrator_name(o.kind)});
  if (o.kind == IntegratorKind::Esdirk) f.pending.push_back({name, "method", o.esdirk_table});
  else f.pending.push_back({name, "max_order", static_cast<long>(o.max_order)});
  f.pending.push_back({name, "output_dt", o.output_dt});
  f.pending.push_back({name, "threads", d.threads});
  std::string kinds;
  for (const auto& k : d.inputs) kinds += (kinds.empty() ? "" : ",") + k;
  f.pending.push_back({name, "inputs", kinds});
  f.begin_swmr();
  w.last_flush = now_s();
  return std::make_unique<RunWriter>(std::move(p));
}

void RunWriter::append(const OutputSample& s) {
  const h5::Quiet quiet;
  Impl& w = *impl_;
  if (!w.group.valid()) throw std::logic_error("RunWriter::append after finish");
  const bool flexible = !w.flexible.empty() && w.rows % w.layout.flexible_every == 0;
  // The chunks these rows start, and those started since the last flush (still in HDF5's cache,
  // written to the file at the next flush), must fit.
  const long long fresh = Impl::new_chunks(w.series, w.rows) + (flexible ? Impl::new_chunks(w.flexible, w.flex_rows) : 0);
  w.file->require(kMargin + w.unflushed + fresh);
  w.unflushed += fresh;
  sample_rows(*w.model, w.layout, s, w.scratch);
  for (size_t i = 0; i < w.series.size(); ++i) w.write_row(w.series[i], w.rows, w.scratch[i].data());
  if (flexible) {
    flexible_rows(*w.model, w.layout, s, w.scratch);
    for (size_t i = 0; i < w.flexible.size(); ++i) w.write_row(w.flexible[i], w.flex_rows, w.scratch[i].data());
    ++w.flex_rows;
  }
  ++w.rows;
  // Flush at most twice a second: output must not dominate a run, yet little is lost on a crash
  // and a watching reader sees the run advance.
  if (now_s() - w.last_flush > 0.5) w.flush();
}

void RunWriter::finish(const RunOutcome& r, double wall_s, const std::vector<std::string>& warnings) {
  const h5::Quiet quiet;
  Impl& w = *impl_;
  ResultsWriter::File& f = *w.file;
  const std::string& name = w.name;
  f.pending.push_back({name, "status", r.status.to_string()});
  f.pending.push_back({name, "wall_time_s", wall_s});
  f.pending.push_back({name, "t_reached", r.t_reached});
  f.pending.push_back({name, "steps", static_cast<long>(r.stats.steps)});
  f.pending.push_back({name, "residual_evals", static_cast<long>(r.stats.residual_evals)});
  f.pending.push_back({name, "factorizations", static_cast<long>(r.stats.factorizations)});
  f.pending.push_back({name, "newton_iters", static_cast<long>(r.stats.newton_iters)});
  f.pending.push_back({name, "newton_fails", static_cast<long>(r.stats.newton_fails)});
  f.pending.push_back({name, "error_test_fails", static_cast<long>(r.stats.error_test_fails)});
  std::string lines;
  for (const auto& x : warnings) lines += (lines.empty() ? "" : "\n") + x;
  f.pending.push_back({name, "warnings", lines});
  w.set_status(r.status.to_string());
  w.flush();
  w.close_quietly();
  f.end_swmr();  // writes the attributes queued above
}

}  // namespace rfem
