#include "writer.hpp"

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
#include <thread>
#include <variant>

#include "writer_impl.hpp"
#include "rfem/version.hpp"

namespace rfem {


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
  std::error_code ec;
  const bool existed = std::filesystem::exists(path, ec);
  file_->lock_fd = claim(path, d.case_path);
  bool created = false;
  try {
    file_->require(kMargin);
    const h5::Handle fapl = latest_fapl();
    // A reader that opens the path between HDF5's creation of the file and its lock (a poller
    // waiting for the file to appear) holds a shared lock for an instant: the creation then fails
    // with EAGAIN, and is tried again for up to a second.
    errno = 0;
    hid_t id = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    for (int k = 0; id < 0 && (errno == EAGAIN || errno == EWOULDBLOCK) && k < 100; ++k) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
      errno = 0;
      id = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    }
    file_->id = h5::file(id, path + ": cannot create results file (is the directory writable?)");
    created = true;
    file_->attribute("/", "rfem_version", std::string(version_string));
    file_->attribute("/", "build", std::string(build_description()));
    file_->attribute("/", "command_line", d.command_line);
    file_->attribute("/", "case_path", d.case_path);
    file_->attribute("/", "case_text", d.case_text);
    file_->attribute("/", "case_effective", d.case_effective);
    file_->attribute("/", "overrides", d.overrides);
    file_->attribute("/", "procedure", d.procedure);
    if (!d.driven_by.empty()) file_->attribute("/", "driven_by", d.driven_by);
    if (d.n >= 0) file_->attribute("/", "n", d.n);
    if (d.n_option >= 0) file_->attribute("/", "n_option", d.n_option);
    file_->attribute("/", "threads", d.threads);
    file_->case_sum = writer_detail::case_checksum(d.case_text, d.overrides, d.n_option);
  } catch (...) {
    // A file that could not be made whole (a full disk, a size limit) is not left behind empty
    // (a file that stood there before is removed only once the creation has truncated it).
    file_->id.reset();
    if (!existed || created) std::filesystem::remove(path, ec);
    throw;
  }
}

ResultsWriter::ResultsWriter(const std::string& path, Reopen) : file_(std::make_shared<File>()) {
  const h5::Quiet quiet;
  file_->path = path;
  if (H5Fis_hdf5(path.c_str()) <= 0) {
    h5::reason();
    throw ResultsError(path + ": not an HDF5 results file");
  }
  file_->lock_fd = claim(path, "");
  file_->require(kMargin);
  const h5::Handle fapl = latest_fapl();
  // A run killed while writing left the file marked as open by a (SWMR) writer: clear the mark, as
  // h5clear -s does (HDF5's file-access property for it; SWMR kept the file consistent).
  hbool_t clear = true;
  h5::check(H5Pset(fapl, "clear_status_flags", &clear), path + ": reopening");
  file_->id = h5::file(H5Fopen(path.c_str(), H5F_ACC_RDWR, fapl), path + ": cannot reopen the results file to resume it");
  file_->case_sum = writer_detail::case_checksum(file_->id, path + ": reading its case");
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
  // Closed, the file is free for other writers at once (not when the last owner of the writer goes).
  if (file_->lock_fd >= 0) {
    ::close(file_->lock_fd);
    file_->lock_fd = -1;
  }
}

namespace {
void put_vector(hid_t g, const char* name, const std::vector<double>& v, const std::string& what) {
  const hsize_t dims[1] = {v.size()};
  const h5::Handle sp = h5::space(H5Screate_simple(1, dims, nullptr), what);
  const h5::Handle dcpl = h5::checked_layout(1, dims, what);
  const h5::Handle ds = h5::dataset(H5Dcreate2(g, name, H5T_NATIVE_DOUBLE, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT), what);
  if (!v.empty()) h5::check(H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), what);
}
}  // namespace

void ResultsWriter::write_refinement(const std::vector<std::string>& quantities, const std::vector<int>& ns,
                                     const std::vector<Refinement>& tables, const RunStatus& status, int modes_at_n) {
  const h5::Quiet quiet;
  File& f = *file_;
  f.end_swmr();
  const std::string what = f.what("writing the refinement tables");
  if (H5Lexists(f.id, "refine", H5P_DEFAULT) > 0) h5::check(H5Ldelete(f.id, "refine", H5P_DEFAULT), what);
  const h5::Handle g = h5::group(H5Gcreate2(f.id, "refine", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), what);
  put_vector(g, modes_at_n > 0 ? "modes" : "n", std::vector<double>(ns.begin(), ns.end()), what);
  h5::write_attribute(g, "status", status.to_string());
  if (modes_at_n > 0) h5::write_attribute(g, "n", static_cast<long>(modes_at_n));
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
      // The last value's error bar (solvers/refinement.hpp; NaN and asymptotic 0 where there is none).
      h5::write_attribute(where, "error", t.error);
      h5::write_attribute(where, "error_space", t.error_space);
      h5::write_attribute(where, "error_time", t.error_time);
      h5::write_attribute(where, "observed_order", t.observed_order());
      h5::write_attribute(where, "asymptotic", static_cast<long>(t.asymptotic));
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
  const h5::Handle dcpl = h5::checked_layout(2, dims, what);
  const h5::Handle ds = h5::dataset(H5Dcreate2(f.id, name.c_str(), H5T_NATIVE_DOUBLE, sp, lcpl, dcpl, H5P_DEFAULT), what);
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

void ResultsWriter::write_attribute(const std::string& object, const std::string& key, double value) {
  const h5::Quiet quiet;
  File& f = *file_;
  f.end_swmr();
  const h5::Handle obj = h5::object(H5Oopen(f.id, object.c_str(), H5P_DEFAULT), f.what("opening " + object));
  h5::write_attribute(obj, key, value);
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

namespace writer_detail {

void queue_run_description(ResultsWriter::File& f, const std::string& name, const RunDescription& d) {
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
}

}  // namespace writer_detail

std::unique_ptr<RunWriter> ResultsWriter::begin_run(const std::string& name, std::shared_ptr<const Model> model,
                                                   const RunDescription& d) {
  if (!model) throw std::invalid_argument("ResultsWriter::begin_run: no model");
  const h5::Quiet quiet;
  File& f = *file_;
  f.end_swmr();  // a new group: not while another run's SWMR lasts
  f.require(2 * kMargin);
  auto p = RunWriter::Impl::make(file_, name, model, d);
  RunWriter::Impl& w = *p;
  const Model& M = *model;
  const h5::Handle lcpl = h5::plist(H5Pcreate(H5P_LINK_CREATE), f.what("creating group " + name));
  h5::check(H5Pset_create_intermediate_group(lcpl, 1), f.what("creating group " + name));  // "n60/kinematic"
  if (H5Lexists(f.id, name.c_str(), H5P_DEFAULT) > 0)  // (a reopened file: the run starts again)
    h5::check(H5Ldelete(f.id, name.c_str(), H5P_DEFAULT), f.what("removing the old group " + name));
  h5::reason();
  w.group = h5::group(H5Gcreate2(f.id, name.c_str(), lcpl, H5P_DEFAULT, H5P_DEFAULT), f.what("cannot create group " + name));
  for (const SeriesInfo& s : w.layout.series) w.series.push_back(w.add_series(s));
  for (const SeriesInfo& s : w.layout.flexible) w.flexible.push_back(w.add_series(s));
  if (w.sensors_info) w.measured.push_back(w.add_series(*w.sensors_info));
  for (const auto& [info, values] : w.layout.constants) {
    const std::string what = w.what("creating " + info.name + " in");
    const hsize_t dims[2] = {values.size() / info.width(), static_cast<hsize_t>(info.width())};
    const h5::Handle sp = h5::space(H5Screate_simple(2, dims, nullptr), what);
    const h5::Handle dcpl = h5::checked_layout(2, dims, what);
    const h5::Handle ds =
        h5::dataset(H5Dcreate2(w.group, info.name.c_str(), H5T_NATIVE_DOUBLE, sp, H5P_DEFAULT, dcpl, H5P_DEFAULT), what);
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
  w.create_checkpoints();
  writer_detail::queue_run_description(f, name, d);
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
  const long long fresh = Impl::new_chunks(w.series, w.rows) + Impl::new_chunks(w.measured, w.rows) +
                          (flexible ? Impl::new_chunks(w.flexible, w.flex_rows) : 0);
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

void RunWriter::append_sensors(const std::vector<double>& row) {
  const h5::Quiet quiet;
  Impl& w = *impl_;
  if (!w.group.valid()) throw std::logic_error("RunWriter::append_sensors after finish");
  if (w.measured.empty() || static_cast<long>(row.size()) != w.measured[0].cols || w.rows < 1)
    throw std::invalid_argument("RunWriter::append_sensors: a row of " + std::to_string(row.size()) +
                                " values where the run's sensors table has " +
                                std::to_string(w.measured.empty() ? 0 : w.measured[0].cols) + " (after append)");
  // The row of the output just appended (rows − 1): its chunk was counted with the output's.
  w.write_row(w.measured[0], w.rows - 1, row.data());
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
