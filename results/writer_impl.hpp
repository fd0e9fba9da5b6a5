#pragma once
// The insides of ResultsWriter and RunWriter, shared by results/writer.cpp (runs as they go) and
// results/checkpoints.cpp (a run's checkpoints, and a run reopened to resume).
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <variant>

#include "h5_impl.hpp"
#include "writer.hpp"

namespace rfem {

namespace writer_detail {

/// The attributes that describe a run, queued for the end of its SWMR writing.
void queue_run_description(ResultsWriter::File& f, const std::string& run, const RunDescription& d);

/// The checksum of what defines a file's model and runs (the case text, its --set overrides, the n
/// asked for), kept in every checkpoint: a checkpoint of another case is refused.
uint64_t case_checksum(const std::string& case_text, const std::string& overrides, long n_option);
/// The same, from the file's attributes.
uint64_t case_checksum(hid_t file, const std::string& what);

inline double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

inline h5::Handle latest_fapl() {  // SWMR needs the latest file format
  h5::Handle fapl = h5::plist(H5Pcreate(H5P_FILE_ACCESS), "file access list");
  h5::check(H5Pset_libver_bounds(fapl, H5F_LIBVER_LATEST, H5F_LIBVER_LATEST), "file access list");
  return fapl;
}

}  // namespace writer_detail

using writer_detail::now_s;
using writer_detail::latest_fapl;

// Room a run's group needs besides its chunks of rows: metadata flushes, the attributes written at
// its end, closing the file (measured: a run group's metadata takes 20–40 kB).
inline constexpr long long kMargin = 64 * 1024;

struct ResultsWriter::File {
  std::string path;
  h5::Handle id;
  int lock_fd = -1;  // holds the open-file-description lock that keeps other rfem writers out
  bool swmr = false;
  uint64_t case_sum = 0;  // writer_detail::case_checksum of the file's case
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
  std::vector<Series> measured;  // the sensors' table (none without sensors): a row per output
  h5::Handle group, status;
  long rows = 0, flex_rows = 0;
  double last_flush = 0.0;
  long long unflushed = 0;  // bytes of chunks started since the last flush
  std::vector<std::vector<double>> scratch;
  std::optional<SeriesInfo> sensors_info;  // the sensors' table, if the case has sensors
  h5::Handle checkpoints;  // 2 slots × (header + state), results/checkpoints.cpp
  long checkpoint_sequence = 0;

  void create_checkpoints();  // (before SWMR: a new dataset)

  // A run's writer on `file` for `name`, before its group is opened or created.
  static std::unique_ptr<Impl> make(const std::shared_ptr<ResultsWriter::File>& file, const std::string& name,
                                    std::shared_ptr<const Model> model, const RunDescription& d) {
    auto p = std::make_unique<Impl>();
    p->file = file;
    p->name = name;
    p->layout = run_layout(*model, d.flexible_every);
    if (!d.sensor_columns.empty())
      p->sensors_info = SeriesInfo{"sensors", d.sensor_columns, d.sensor_units,
                                   "the case's [[sensors]] at every output, as measured (noise, resolution)"};
    p->model = std::move(model);
    return p;
  }

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
    h5::checksummed(plist, w);  // damaged rows fail on read instead of reading as numbers
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
      for (auto* v : {&series, &flexible, &measured})
        for (auto& s : *v) h5::check(H5Dflush(s.dset), what("flushing " + s.name + " of"));
      if (status.valid()) h5::check(H5Dflush(status), what("flushing the status of"));
    }
    file->flush();
    last_flush = now_s();
    unflushed = 0;
  }

  // Closes the datasets and the group (before the file leaves SWMR mode); never throws.
  void close_quietly() {
    for (auto* v : {&series, &flexible, &measured})
      for (auto& s : *v) s.dset.reset();
    status.reset();
    checkpoints.reset();
    group.reset();
  }
};

}  // namespace rfem
