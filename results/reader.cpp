#include "reader.hpp"

#include "h5_impl.hpp"

namespace rfem {

std::vector<double> Table::column(long c) const {
  std::vector<double> out(static_cast<size_t>(rows));
  for (long r = 0; r < rows; ++r) out[static_cast<size_t>(r)] = at(r, c);
  return out;
}

namespace {
constexpr unsigned kSwmrReadAttempts = 20;
}  // namespace

struct ResultsReader::Impl {
  std::string path;
  h5::Handle file;
};

ResultsReader::ResultsReader(const std::string& path) : impl_(std::make_unique<Impl>()) {
  const h5::Quiet quiet;
  impl_->path = path;
  const h5::Handle fapl = h5::plist(H5Pcreate(H5P_FILE_ACCESS), path);
  // A finished file opens without SWMR: damage is then an error at once. Only a file marked as
  // written (a run writing it, or killed while it did) needs SWMR read, whose checksum failures
  // HDF5 retries with doubling sleeps (100 tries by default: hours): a few tries (about 1 ms of
  // sleep) outlast a writer's flush, and a damaged file fails.
  hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl);
  if (id < 0) {
    h5::reason();
    h5::check(H5Pset_metadata_read_attempts(fapl, kSwmrReadAttempts), path + ": file access list");
    id = H5Fopen(path.c_str(), H5F_ACC_RDONLY | H5F_ACC_SWMR_READ, fapl);
  }
  impl_->file = h5::file(id, path + ": not a readable HDF5 results file");
}

ResultsReader::~ResultsReader() {
  if (impl_) {
    const h5::Quiet quiet;
    impl_->file.reset();
  }
}
ResultsReader::ResultsReader(ResultsReader&&) noexcept = default;
ResultsReader& ResultsReader::operator=(ResultsReader&&) noexcept = default;

const std::string& ResultsReader::path() const { return impl_->path; }

bool ResultsReader::has(const std::string& object) const {
  const h5::Quiet quiet;
  // Every link on the way must exist (H5Lexists fails on a missing intermediate group).
  for (size_t pos = 0;;) {
    pos = object.find('/', pos + 1);
    const std::string prefix = object.substr(0, pos);
    if (!prefix.empty() && prefix != "/" && H5Lexists(impl_->file, prefix.c_str(), H5P_DEFAULT) <= 0) return false;
    if (pos == std::string::npos) break;
  }
  return H5Oexists_by_name(impl_->file, object.c_str(), H5P_DEFAULT) > 0;
}

namespace {

// Opens a 2-D float dataset and reads its dimensions (every failure a ResultsError).
h5::Handle open_table(hid_t file, const std::string& object, const std::string& what, hsize_t dims[2]) {
  h5::Handle d = h5::dataset(H5Dopen2(file, object.c_str(), H5P_DEFAULT), what);
  const h5::Handle s = h5::space(H5Dget_space(d), what);
  const int rank = H5Sget_simple_extent_ndims(s);
  if (rank != 2) throw ResultsError(what + ": a table has 2 dimensions, this one " + std::to_string(rank));
  h5::check(H5Sget_simple_extent_dims(s, dims, nullptr), what);
  const h5::Handle t = h5::type(H5Dget_type(d), what);
  if (H5Tget_class(t) != H5T_FLOAT) throw ResultsError(what + ": not a table of numbers");
  return d;
}

}  // namespace

std::pair<long, long> ResultsReader::shape(const std::string& object) const {
  const h5::Quiet quiet;
  const std::string what = impl_->path + ": " + object;
  if (!has(object)) throw ResultsError(what + ": no such dataset");
  hsize_t dims[2] = {0, 0};
  open_table(impl_->file, object, what, dims);
  return {static_cast<long>(dims[0]), static_cast<long>(dims[1])};
}

std::vector<std::string> ResultsReader::children(const std::string& group) const {
  const h5::Quiet quiet;
  const std::string what = impl_->path + ": " + group;
  if (group != "/" && !has(group)) throw ResultsError(what + ": no such group");
  const h5::Handle g = h5::group(H5Gopen2(impl_->file, group.c_str(), H5P_DEFAULT), what);
  H5G_info_t info;
  h5::check(H5Gget_info(g, &info), what);
  std::vector<std::string> out;
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    const ssize_t len = H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
    if (len < 0) throw ResultsError(what + ": cannot list the group");
    std::string name(static_cast<size_t>(len) + 1, '\0');
    H5Lget_name_by_idx(g, ".", H5_INDEX_NAME, H5_ITER_INC, i, name.data(), name.size(), H5P_DEFAULT);
    name.resize(static_cast<size_t>(len));
    out.push_back(name);
  }
  return out;
}

Table ResultsReader::table(const std::string& object) const {
  const h5::Quiet quiet;
  const std::string what = impl_->path + ": " + object;
  if (!has(object)) throw ResultsError(what + ": no such dataset");
  hsize_t dims[2] = {0, 0};
  const h5::Handle d = open_table(impl_->file, object, what, dims);
  Table out;
  out.rows = static_cast<long>(dims[0]);
  out.cols = static_cast<long>(dims[1]);
  out.data.resize(dims[0] * dims[1]);
  if (!out.data.empty()) h5::check(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data.data()), what);
  return out;
}

Table ResultsReader::rows(const std::string& object, long first, long count) const {
  const h5::Quiet quiet;
  const std::string what = impl_->path + ": " + object;
  if (!has(object)) throw ResultsError(what + ": no such dataset");
  hsize_t dims[2] = {0, 0};
  const h5::Handle d = open_table(impl_->file, object, what, dims);
  if (first < 0 || count < 0 || static_cast<hsize_t>(first + count) > dims[0])
    throw ResultsError(what + ": has " + std::to_string(dims[0]) + " rows, not rows " + std::to_string(first + 1) + " to " +
                       std::to_string(first + count));
  Table out;
  out.rows = count;
  out.cols = static_cast<long>(dims[1]);
  out.data.resize(static_cast<size_t>(count) * dims[1]);
  if (out.data.empty()) return out;
  const h5::Handle fspace = h5::space(H5Dget_space(d), what);
  const hsize_t start[2] = {static_cast<hsize_t>(first), 0}, size[2] = {static_cast<hsize_t>(count), dims[1]};
  h5::check(H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, nullptr, size, nullptr), what);
  const h5::Handle mspace = h5::space(H5Screate_simple(2, size, nullptr), what);
  h5::check(H5Dread(d, H5T_NATIVE_DOUBLE, mspace, fspace, H5P_DEFAULT, out.data.data()), what);
  return out;
}

std::string ResultsReader::attribute(const std::string& object, const std::string& key, const std::string& fallback) const {
  const h5::Quiet quiet;
  if (object != "/" && !has(object)) return fallback;
  const h5::Handle o = h5::object(H5Oopen(impl_->file, object.c_str(), H5P_DEFAULT), impl_->path + ": " + object);
  std::string v;
  try {
    if (h5::read_string_attribute(o, key, v)) return v;
  } catch (const ResultsError&) {
  }
  return fallback;
}

double ResultsReader::number(const std::string& object, const std::string& key, double fallback) const {
  const h5::Quiet quiet;
  if (object != "/" && !has(object)) return fallback;
  const h5::Handle o = h5::object(H5Oopen(impl_->file, object.c_str(), H5P_DEFAULT), impl_->path + ": " + object);
  if (H5Aexists(o, key.c_str()) <= 0) return fallback;
  const hid_t a = H5Aopen(o, key.c_str(), H5P_DEFAULT);
  if (a < 0) return fallback;
  const h5::Handle attr = h5::attribute(a, impl_->path + ": " + key);
  const h5::Handle t = h5::type(H5Aget_type(attr), impl_->path + ": " + key);
  const h5::Handle s = h5::space(H5Aget_space(attr), impl_->path + ": " + key);
  const H5T_class_t c = H5Tget_class(t);
  double v = fallback;
  if ((c == H5T_INTEGER || c == H5T_FLOAT) && H5Sget_simple_extent_npoints(s) == 1 && H5Aread(attr, H5T_NATIVE_DOUBLE, &v) < 0)
    v = fallback;
  h5::reason();
  return v;
}

}  // namespace rfem
