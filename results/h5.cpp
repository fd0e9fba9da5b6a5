#include "h5_impl.hpp"

#include <algorithm>

namespace rfem {
void disable_hdf5_exit_cleanup() { H5dont_atexit(); }
}  // namespace rfem

namespace rfem::h5 {

Quiet::Quiet() {
  H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  H5Eclear2(H5E_DEFAULT);
}

Quiet::~Quiet() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

namespace {
herr_t innermost(unsigned n, const H5E_error2_t* e, void* out) {
  if (n == 0 && e->desc) *static_cast<std::string*>(out) = e->desc;  // the failing call's own words
  return 0;
}
}  // namespace

std::string reason() {
  std::string msg;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, innermost, &msg);
  H5Eclear2(H5E_DEFAULT);
  // A failed system call: HDF5 quotes the system's words ("error message = 'No space left on
  // device'") inside a long description; those words are the reason.
  const std::string tag = "error message = '";
  if (const auto at = msg.find(tag); at != std::string::npos) {
    const auto end = msg.find('\'', at + tag.size());
    if (end != std::string::npos) msg = msg.substr(at + tag.size(), end - at - tag.size());
  }
  if (const auto nl = msg.find('\n'); nl != std::string::npos) msg.resize(nl);
  return msg.empty() ? "HDF5 error" : msg;
}

hid_t check(hid_t id, const std::string& what) {
  if (id < 0) throw ResultsError(what + ": " + reason());
  return id;
}

void check(herr_t status, const std::string& what) {
  if (status < 0) throw ResultsError(what + ": " + reason());
}

bool Handle::reset() {
  if (id_ < 0) return true;
  const Quiet quiet;  // (a destructor's close reports nothing: what failed was reported before)
  const bool ok = close_(id_) >= 0;
  id_ = -1;
  return ok;
}

void Handle::close(const std::string& what) {
  if (id_ < 0) return;
  const herr_t status = close_(id_);
  id_ = -1;
  check(status, what);
}

Handle file(hid_t id, const std::string& what) { return {check(id, what), H5Fclose}; }
Handle group(hid_t id, const std::string& what) { return {check(id, what), H5Gclose}; }
Handle dataset(hid_t id, const std::string& what) { return {check(id, what), H5Dclose}; }
Handle space(hid_t id, const std::string& what) { return {check(id, what), H5Sclose}; }
Handle type(hid_t id, const std::string& what) { return {check(id, what), H5Tclose}; }
Handle plist(hid_t id, const std::string& what) { return {check(id, what), H5Pclose}; }
Handle attribute(hid_t id, const std::string& what) { return {check(id, what), H5Aclose}; }
Handle object(hid_t id, const std::string& what) { return {check(id, what), H5Oclose}; }

Handle string_type() {
  Handle t = type(H5Tcopy(H5T_C_S1), "string type");
  check(H5Tset_size(t, H5T_VARIABLE), "string type");
  check(H5Tset_cset(t, H5T_CSET_UTF8), "string type");
  return t;
}

namespace {
// A new attribute `key` of `obj` (an existing one of that name replaced).
Handle new_attribute(hid_t obj, const std::string& key, hid_t type, hid_t space) {
  const htri_t exists = H5Aexists(obj, key.c_str());
  check(static_cast<herr_t>(exists), "attribute " + key);
  if (exists > 0) check(H5Adelete(obj, key.c_str()), "attribute " + key);
  return attribute(H5Acreate2(obj, key.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), "attribute " + key);
}
}  // namespace

void write_attribute(hid_t obj, const std::string& key, const std::string& value) {
  const Handle t = string_type();
  const Handle s = space(H5Screate(H5S_SCALAR), "attribute " + key);
  const Handle a = new_attribute(obj, key, t, s);
  const char* p = value.c_str();
  check(H5Awrite(a, t, &p), "attribute " + key);
}

void write_attribute(hid_t obj, const std::string& key, const std::vector<std::string>& values) {
  const Handle t = string_type();
  if (values.empty()) {  // an empty list (a structure without joints): a null dataspace, nothing to write
    const Handle s = space(H5Screate(H5S_NULL), "attribute " + key);
    const Handle a = new_attribute(obj, key, t, s);
    return;
  }
  const hsize_t dims[1] = {values.size()};
  const Handle s = space(H5Screate_simple(1, dims, nullptr), "attribute " + key);
  const Handle a = new_attribute(obj, key, t, s);
  std::vector<const char*> p;
  for (const auto& v : values) p.push_back(v.c_str());
  check(H5Awrite(a, t, p.data()), "attribute " + key);
}

void write_attribute(hid_t obj, const std::string& key, long value) {
  const Handle s = space(H5Screate(H5S_SCALAR), "attribute " + key);
  const Handle a = new_attribute(obj, key, H5T_NATIVE_LONG, s);
  check(H5Awrite(a, H5T_NATIVE_LONG, &value), "attribute " + key);
}

void write_attribute(hid_t obj, const std::string& key, double value) {
  const Handle s = space(H5Screate(H5S_SCALAR), "attribute " + key);
  const Handle a = new_attribute(obj, key, H5T_NATIVE_DOUBLE, s);
  check(H5Awrite(a, H5T_NATIVE_DOUBLE, &value), "attribute " + key);
}

bool read_string_attribute(hid_t obj, const std::string& key, std::string& value) {
  if (H5Aexists(obj, key.c_str()) <= 0) return false;
  const Handle a = attribute(H5Aopen(obj, key.c_str(), H5P_DEFAULT), "attribute " + key);
  const Handle t = type(H5Aget_type(a), "attribute " + key);
  if (H5Tget_class(t) != H5T_STRING) return false;
  const Handle s = space(H5Aget_space(a), "attribute " + key);
  if (H5Sget_simple_extent_npoints(s) != 1) return false;
  if (H5Tis_variable_str(t) > 0) {
    char* p = nullptr;
    check(H5Aread(a, t, &p), "attribute " + key);
    value = p ? p : "";
    if (p) H5free_memory(p);
    return true;
  }
  const size_t n = H5Tget_size(t);
  std::string buf(n, '\0');
  check(H5Aread(a, t, buf.data()), "attribute " + key);
  value = buf.substr(0, std::min(buf.find('\0'), buf.size()));
  return true;
}

Handle checked_layout(int rank, const hsize_t* dims, const std::string& what) {
  Handle plist = h5::plist(H5Pcreate(H5P_DATASET_CREATE), what);
  std::vector<hsize_t> chunk(dims, dims + rank);
  hsize_t values = 1;
  for (hsize_t& c : chunk) {
    if (c == 0) return plist;
    if (&c != &chunk.front()) values *= c;
  }
  if (rank > 0) chunk[0] = std::max<hsize_t>(1, std::min<hsize_t>(chunk[0], (hsize_t{1} << 16) / std::max<hsize_t>(1, values)));
  check(H5Pset_chunk(plist, rank, chunk.data()), what);
  checksummed(plist, what);
  return plist;
}

void checksummed(hid_t dcpl, const std::string& what) { check(H5Pset_fletcher32(dcpl), what); }

}  // namespace rfem::h5
