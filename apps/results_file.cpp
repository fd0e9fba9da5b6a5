#include "apps/results_file.hpp"

#include <stdexcept>

#include "solvers/statics.hpp"

namespace rfem::app {

void write_attribute(hid_t obj, const std::string& key, const std::string& value) {
  if (H5Aexists(obj, key.c_str()) > 0) H5Adelete(obj, key.c_str());
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, std::max<size_t>(1, value.size()));
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attr = H5Acreate2(obj, key.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attr, type, value.c_str());
  H5Aclose(attr);
  H5Sclose(space);
  H5Tclose(type);
}

void write_attribute(hid_t obj, const std::string& key, double value) {
  if (H5Aexists(obj, key.c_str()) > 0) H5Adelete(obj, key.c_str());
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attr = H5Acreate2(obj, key.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attr, H5T_NATIVE_DOUBLE, &value);
  H5Aclose(attr);
  H5Sclose(space);
}

ResultsFile::ResultsFile(const std::string& path) : path_(path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by us, once
  file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file_ < 0) throw std::runtime_error(path + ": cannot create results file");
}
ResultsFile::~ResultsFile() {
  if (file_ >= 0) H5Fclose(file_);
}
void ResultsFile::attribute(const std::string& key, const std::string& value) { write_attribute(file_, key, value); }
void ResultsFile::flush() { H5Fflush(file_, H5F_SCOPE_GLOBAL); }

Eigen::Vector3d tip_deflection(const Model& model, const VecX& q) {
  const Vec6 t = tip_motion(model, q);
  return {t[1], t[2], t[3]};
}

RunGroup::RunGroup(ResultsFile& file, const std::string& name, const Model& model, int flexible_every)
    : file_(file), model_(model), flexible_every_(flexible_every), last_flush_(std::chrono::steady_clock::now()) {
  const hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);  // "n60/kinematic" creates "n60" as needed
  H5Pset_create_intermediate_group(lcpl, 1);
  group_ = H5Gcreate2(file.id(), name.c_str(), lcpl, H5P_DEFAULT, H5P_DEFAULT);
  H5Pclose(lcpl);
  if (group_ < 0) throw std::runtime_error(file.path() + ": cannot create group " + name);
  const int m = model.m();
  std::string joints;
  for (const auto& j : model.joints) joints += (joints.empty() ? "" : ",") + j.name;
  add_series("time", 1, "t [s]");
  add_series("joint_q", m, joints);
  add_series("joint_v", m, joints);
  add_series("joint_a", m, joints);
  add_series("joint_tau", m, joints);
  add_series("tip", 6, "ux,uy,uz [m],rx,ry,rz [rad] in {r}");
  add_series("tip_deflection", 3, "u1 (along y of {r}) [m],u2 (along z) [m],theta (torsion) [rad]");
  add_series("energy", 6, "kinetic,elastic,gravity,input_work,dissipated,balance [J]");
  if (flexible_every_ > 0 && model.n() > 0) {
    add_series("flexible_time", 1, "t [s]");
    add_series("flexible_q", 6 * model.n(), "rfe k: x1,x2,x3,phi1,phi2,phi3 for k = 1..n");
  }
  write_attribute(group_, "n", static_cast<double>(model.n()));
  write_attribute(group_, "m", static_cast<double>(m));
  write_attribute(group_, "joints", joints);
  write_attribute(group_, "status", std::string("running"));
}

RunGroup::~RunGroup() {
  flush();
  for (auto& [k, s] : series_) H5Dclose(s.dset);
  H5Gclose(group_);
}

void RunGroup::add_series(const std::string& name, int cols, const std::string& columns) {
  const hsize_t dims[2] = {0, static_cast<hsize_t>(std::max(cols, 1))};
  const hsize_t maxd[2] = {H5S_UNLIMITED, dims[1]};
  const hid_t space = H5Screate_simple(2, dims, maxd);
  const hid_t plist = H5Pcreate(H5P_DATASET_CREATE);
  const hsize_t chunk[2] = {std::max<hsize_t>(1, std::min<hsize_t>(256, (1 << 16) / dims[1])), dims[1]};
  H5Pset_chunk(plist, 2, chunk);
  const hid_t d = H5Dcreate2(group_, name.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, plist, H5P_DEFAULT);
  H5Pclose(plist);
  H5Sclose(space);
  write_attribute(d, "columns", columns);
  series_[name] = Series{d, std::max(cols, 1)};
}

void RunGroup::write_row(const std::string& name, long row, const double* data) {
  Series& s = series_.at(name);
  const hsize_t size[2] = {static_cast<hsize_t>(row + 1), static_cast<hsize_t>(s.cols)};
  H5Dset_extent(s.dset, size);
  const hid_t fspace = H5Dget_space(s.dset);
  const hsize_t start[2] = {static_cast<hsize_t>(row), 0}, count[2] = {1, static_cast<hsize_t>(s.cols)};
  H5Sselect_hyperslab(fspace, H5S_SELECT_SET, start, nullptr, count, nullptr);
  const hid_t mspace = H5Screate_simple(2, count, nullptr);
  H5Dwrite(s.dset, H5T_NATIVE_DOUBLE, mspace, fspace, H5P_DEFAULT, data);
  H5Sclose(mspace);
  H5Sclose(fspace);
}

void RunGroup::append(const OutputSample& s) {
  const int m = model_.m();
  const VecX qb = s.q.tail(m), vb = s.v.tail(m), ab = s.a.tail(m);
  write_row("time", rows_, &s.t);
  if (m > 0) {
    write_row("joint_q", rows_, qb.data());
    write_row("joint_v", rows_, vb.data());
    write_row("joint_a", rows_, ab.data());
    write_row("joint_tau", rows_, s.tau.data());
  } else {
    const double z = 0.0;
    for (const char* k : {"joint_q", "joint_v", "joint_a", "joint_tau"}) write_row(k, rows_, &z);
  }
  const Vec6 tip = tip_motion(model_, s.q);
  write_row("tip", rows_, tip.data());
  const Eigen::Vector3d u = tip_deflection(model_, s.q);
  write_row("tip_deflection", rows_, u.data());
  const double total = s.energy.kinetic + s.energy.elastic + s.energy.gravity;
  const double e[6] = {s.energy.kinetic, s.energy.elastic, s.energy.gravity, s.input_work, s.dissipated,
                       total + s.dissipated - s.input_work};
  write_row("energy", rows_, e);
  if (flexible_every_ > 0 && model_.n() > 0 && rows_ % flexible_every_ == 0) {
    write_row("flexible_time", flex_rows_, &s.t);
    write_row("flexible_q", flex_rows_, s.q.data());
    ++flex_rows_;
  }
  ++rows_;
  // Flush at most twice a second: output must not dominate a run, yet little is lost on a crash.
  if (std::chrono::steady_clock::now() - last_flush_ > std::chrono::milliseconds(500)) flush();
}

void RunGroup::attribute(const std::string& key, const std::string& value) { write_attribute(group_, key, value); }
void RunGroup::attribute(const std::string& key, double value) { write_attribute(group_, key, value); }
void RunGroup::flush() {
  file_.flush();
  last_flush_ = std::chrono::steady_clock::now();
}

}  // namespace rfem::app
