#include "apps/results_file.hpp"

#include <stdexcept>

#include "solvers/statics.hpp"

namespace rfem::app {

namespace {
// Variable-length UTF-8: h5py reads these as str (fixed-length ASCII comes back as bytes).
hid_t string_type() {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, H5T_VARIABLE);
  H5Tset_cset(type, H5T_CSET_UTF8);
  return type;
}
}  // namespace

void write_attribute(hid_t obj, const std::string& key, const std::string& value) {
  if (H5Aexists(obj, key.c_str()) > 0) H5Adelete(obj, key.c_str());
  const hid_t type = string_type();
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attr = H5Acreate2(obj, key.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
  const char* p = value.c_str();
  H5Awrite(attr, type, &p);
  H5Aclose(attr);
  H5Sclose(space);
  H5Tclose(type);
}

void write_attribute(hid_t obj, const std::string& key, const std::vector<std::string>& values) {
  if (H5Aexists(obj, key.c_str()) > 0) H5Adelete(obj, key.c_str());
  const hid_t type = string_type();
  const hsize_t dims[1] = {values.size()};
  const hid_t space = H5Screate_simple(1, dims, nullptr);
  const hid_t attr = H5Acreate2(obj, key.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT);
  std::vector<const char*> p;
  for (const auto& v : values) p.push_back(v.c_str());
  H5Awrite(attr, type, p.data());
  H5Aclose(attr);
  H5Sclose(space);
  H5Tclose(type);
}

void write_attribute(hid_t obj, const std::string& key, long value) {
  if (H5Aexists(obj, key.c_str()) > 0) H5Adelete(obj, key.c_str());
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attr = H5Acreate2(obj, key.c_str(), H5T_NATIVE_LONG, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attr, H5T_NATIVE_LONG, &value);
  H5Aclose(attr);
  H5Sclose(space);
}

void write_attribute(hid_t obj, const std::string& key, double value) {
  if (H5Aexists(obj, key.c_str()) > 0) H5Adelete(obj, key.c_str());
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attr = H5Acreate2(obj, key.c_str(), H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT);
  H5Awrite(attr, H5T_NATIVE_DOUBLE, &value);
  H5Aclose(attr);
  H5Sclose(space);
}

namespace {
hid_t latest_fapl() {  // SWMR needs the latest file format
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
  H5Pset_libver_bounds(fapl, H5F_LIBVER_LATEST, H5F_LIBVER_LATEST);
  return fapl;
}
}  // namespace

ResultsFile::ResultsFile(const std::string& path) : path_(path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors are reported by us, once
  const hid_t fapl = latest_fapl();
  file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
  H5Pclose(fapl);
  if (file_ < 0) throw std::runtime_error(path + ": cannot create results file (is the directory writable?)");
}
ResultsFile::~ResultsFile() {
  if (swmr_) end_swmr();
  if (file_ >= 0) H5Fclose(file_);
}
void ResultsFile::attribute(const std::string& key, const std::string& value) { attribute("/", key, Value(value)); }
void ResultsFile::flush() { H5Fflush(file_, H5F_SCOPE_GLOBAL); }

void ResultsFile::attribute(const std::string& path, const std::string& key, const Value& value) {
  if (swmr_) {
    pending_.push_back({path, key, value});
    return;
  }
  const hid_t obj = H5Oopen(file_, path.c_str(), H5P_DEFAULT);
  if (obj < 0) return;
  std::visit([&](const auto& v) { write_attribute(obj, key, v); }, value);
  H5Oclose(obj);
}

void ResultsFile::begin_swmr() {
  if (swmr_) return;
  H5Fflush(file_, H5F_SCOPE_GLOBAL);
  swmr_ = H5Fstart_swmr_write(file_) >= 0;
}

void ResultsFile::end_swmr() {
  if (!swmr_) return;
  H5Fclose(file_);
  // Readers that watched the run (SWMR, shared locks) may still have the file open: reopen without
  // file locks for the attributes and the next run's group (a watcher reopens to see them).
  const hid_t fapl = latest_fapl();
  H5Pset_file_locking(fapl, false, true);
  file_ = H5Fopen(path_.c_str(), H5F_ACC_RDWR, fapl);
  H5Pclose(fapl);
  swmr_ = false;
  if (file_ < 0) throw std::runtime_error(path_ + ": cannot reopen the results file");
  for (const auto& p : pending_) attribute(p.path, p.key, p.value);
  pending_.clear();
  flush();
}

Eigen::Vector3d tip_deflection(const Model& model, int l, const VecX& q) {
  const Vec6 t = tip_motion(model, l, q);
  return {t[1], t[2], t[3]};
}

namespace {
// A constant 2-D dataset (rows × columns) with its columns, units and description.
void constant_dataset(hid_t group, const std::string& name, const std::vector<double>& rows_cols, hsize_t cols,
                      const std::vector<std::string>& columns, const std::vector<std::string>& units, const std::string& what) {
  const hsize_t dims[2] = {rows_cols.size() / cols, cols};
  const hid_t sp = H5Screate_simple(2, dims, nullptr);
  const hid_t d = H5Dcreate2(group, name.c_str(), H5T_NATIVE_DOUBLE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, rows_cols.data());
  write_attribute(d, "columns", columns);
  write_attribute(d, "units", units);
  write_attribute(d, "description", what);
  H5Dclose(d);
  H5Sclose(sp);
}
}  // namespace

RunGroup::RunGroup(ResultsFile& file, const std::string& name, const Model& model, int flexible_every)
    : file_(file), model_(model), name_(name), flexible_every_(flexible_every), last_flush_(std::chrono::steady_clock::now()) {
  if (file.swmr()) file.end_swmr();  // a new group: not while another run's SWMR lasts
  const hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);  // "n60/kinematic" creates "n60" as needed
  H5Pset_create_intermediate_group(lcpl, 1);
  group_ = H5Gcreate2(file.id(), name.c_str(), lcpl, H5P_DEFAULT, H5P_DEFAULT);
  H5Pclose(lcpl);
  if (group_ < 0) throw std::runtime_error(file.path() + ": cannot create group " + name);
  const int m = model.m(), n = model.n();
  std::vector<std::string> jn, jt, ju, rate, acc, tau, jp, jpu;
  for (const auto& j : model.joints) {
    const bool rev = j.type == JointType::Revolute;
    jn.push_back(j.name);
    jt.push_back(rev ? "revolute" : "prismatic");
    ju.push_back(rev ? "rad" : "m");
    rate.push_back(rev ? "rad/s" : "m/s");
    acc.push_back(rev ? "rad/s^2" : "m/s^2");
    tau.push_back(rev ? "N m" : "N");
    for (const char* c : {".x", ".y", ".z"}) {
      jp.push_back(j.name + c);
      jpu.push_back("m");
    }
  }
  add_series("time", {"t"}, {"s"});
  add_series("joint_q", jn, ju, "joint coordinates");
  add_series("joint_v", jn, rate, "joint rates");
  add_series("joint_a", jn, acc, "joint accelerations (of the integrator's continuous solution)");
  add_series("joint_tau", jn, tau, "applied torque/force (force input) or required (kinematic input)");
  add_series("joint_position", jp, jpu, "origin of each joint's frame (of the body it moves) in the inertial frame {0}");
  add_series("energy", {"kinetic", "elastic", "gravity", "input_work", "dissipated", "balance"},
             {"J", "J", "J", "J", "J", "J"}, "balance = kinetic + elastic + gravity + dissipated - input_work");
  add_series("momentum", {"px", "py", "pz", "Lx", "Ly", "Lz"}, {"kg m/s", "kg m/s", "kg m/s", "kg m2/s", "kg m2/s", "kg m2/s"},
             "linear momentum and angular momentum about the origin of {0} of every body (drive rotors left out)");
  add_series("centre_of_mass", {"x", "y", "z"}, {"m", "m", "m"}, "centre of mass of every body in {0}");
  if (flexible_every_ > 0 && n > 0) add_series("flexible_time", {"t"}, {"s"});
  // Per link, in links/NAME/; the last link's also at the top (soft links): the layout of one link.
  for (const MountedLink& L : model.links) {
    const std::string g = "links/" + L.name + "/";
    add_series(g + "tip", {"ux", "uy", "uz", "rx", "ry", "rz"}, {"m", "m", "m", "rad", "rad", "rad"},
               "free end on the elastic axis: displacement from undeformed and rotation φ of rfe_n, in {r} axes");
    add_series(g + "tip_position", {"x", "y", "z"}, {"m", "m", "m"}, "free end on the elastic axis, in the inertial frame {0}");
    add_series(g + "tip_deflection", {"u1", "u2", "theta"}, {"m", "m", "rad"},
               "the paper's tip deflections: u1 along y of {r}, u2 along z of {r}, theta the torsion phi1 of rfe_n");
    {
      std::vector<std::string> cols, units;
      for (size_t i = 1; i <= L.d.payloads.size(); ++i)
        for (const char* c : {".x", ".y", ".z"}) {
          cols.push_back("payload" + std::to_string(i) + c);
          units.push_back("m");
        }
      if (!cols.empty())
        add_series(g + "payload_position", cols, units, "reference point of each payload (on the elastic axis) in {0}");
    }
    if (L.n() == 0) continue;
    if (flexible_every_ > 0) {
      std::vector<std::string> cols, units;
      for (int k = 1; k <= L.n(); ++k)
        for (const char* c : {"x1", "x2", "x3", "phi1", "phi2", "phi3"}) {
          cols.push_back("rfe" + std::to_string(k) + "." + c);
          units.push_back(c[0] == 'x' ? "m" : "rad");
        }
      add_series(g + "flexible_q", cols, units,
                 "rfe coordinates [2.2]: mass-centre displacement from rfe_centre and angles of R = RotY(phi2) "
                 "RotZ(phi3) RotX(phi1), in {r} axes");
    }
    std::vector<double> c;  // the undeformed mass centres in {r}: flexible_q is relative to these
    for (const auto& r : L.d.rfes) c.insert(c.end(), {r.centre[0], r.centre[1], r.centre[2]});
    constant_dataset(group_, g + "rfe_centre", c, 3, {"x", "y", "z"}, {"m", "m", "m"},
                     "undeformed mass centre of rfe k (row k-1) in {r}");
  }
  if (!model.links.empty()) {
    const std::string g = "links/" + model.links.back().name + "/";
    for (const char* d : {"tip", "tip_position", "tip_deflection", "rfe_centre", "flexible_q", "payload_position"})
      if (H5Lexists(group_, (g + d).c_str(), H5P_DEFAULT) > 0) H5Lcreate_soft((g + d).c_str(), group_, d, H5P_DEFAULT, H5P_DEFAULT);
  }
  {  // the live status: a fixed-size string, writable while the file is in SWMR mode
    const hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, 256);
    const hid_t sp = H5Screate(H5S_SCALAR);
    status_ = H5Dcreate2(group_, "status_now", type, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    H5Sclose(sp);
    H5Tclose(type);
  }
  std::vector<std::string> link_names;
  for (const MountedLink& L : model.links) link_names.push_back(L.name);
  write_attribute(group_, "n", static_cast<long>(n));
  write_attribute(group_, "m", static_cast<long>(m));
  write_attribute(group_, "joint_names", jn);
  write_attribute(group_, "joint_types", jt);
  write_attribute(group_, "joint_units", ju);
  if (!link_names.empty()) write_attribute(group_, "link_names", link_names);
  write_attribute(group_, "status", std::string("running"));
  status("running");
  file.begin_swmr();
}

RunGroup::~RunGroup() { close(); }

void RunGroup::close() {
  if (group_ < 0) return;
  flush();
  for (auto& [k, s] : series_) H5Dclose(s.dset);
  series_.clear();
  if (status_ >= 0) H5Dclose(status_);
  H5Gclose(group_);
  group_ = status_ = -1;
}

void RunGroup::status(const std::string& s) {
  if (status_ < 0) return;
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, 256);
  char buf[256] = {0};
  s.copy(buf, 255);
  H5Dwrite(status_, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
  H5Tclose(type);
}

void RunGroup::add_series(const std::string& name, const std::vector<std::string>& columns,
                          const std::vector<std::string>& units, const std::string& description) {
  const int cols = std::max<int>(1, static_cast<int>(columns.size()));
  const hsize_t dims[2] = {0, static_cast<hsize_t>(cols)};
  const hsize_t maxd[2] = {H5S_UNLIMITED, dims[1]};
  const hid_t space = H5Screate_simple(2, dims, maxd);
  const hid_t plist = H5Pcreate(H5P_DATASET_CREATE);
  const hsize_t chunk[2] = {std::max<hsize_t>(1, std::min<hsize_t>(256, (1 << 16) / dims[1])), dims[1]};
  H5Pset_chunk(plist, 2, chunk);
  const hid_t lcpl = H5Pcreate(H5P_LINK_CREATE);  // "links/NAME/tip" creates its groups
  H5Pset_create_intermediate_group(lcpl, 1);
  const hid_t d = H5Dcreate2(group_, name.c_str(), H5T_NATIVE_DOUBLE, space, lcpl, plist, H5P_DEFAULT);
  H5Pclose(lcpl);
  H5Pclose(plist);
  H5Sclose(space);
  write_attribute(d, "columns", columns.empty() ? std::vector<std::string>{"(none)"} : columns);
  write_attribute(d, "units", units.empty() ? std::vector<std::string>{""} : units);
  if (!description.empty()) write_attribute(d, "description", description);
  series_[name] = Series{d, cols};
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
  const VecX qb = model_.joint_coords(s.q), vb = model_.joint_coords(s.v), ab = model_.joint_coords(s.a);
  write_row("time", rows_, &s.t);
  if (m > 0) {
    write_row("joint_q", rows_, qb.data());
    write_row("joint_v", rows_, vb.data());
    write_row("joint_a", rows_, ab.data());
    write_row("joint_tau", rows_, s.tau.data());
    const std::vector<Vec3> jp = joint_positions(model_, s.q);
    std::vector<double> flat;
    for (const Vec3& p : jp) flat.insert(flat.end(), {p[0], p[1], p[2]});
    write_row("joint_position", rows_, flat.data());
  } else {
    const double z = 0.0;
    for (const char* k : {"joint_q", "joint_v", "joint_a", "joint_tau", "joint_position"}) write_row(k, rows_, &z);
  }
  const double total = s.energy.kinetic + s.energy.elastic + s.energy.gravity;
  const double e[6] = {s.energy.kinetic, s.energy.elastic, s.energy.gravity, s.input_work, s.dissipated,
                       total + s.dissipated - s.input_work};
  write_row("energy", rows_, e);
  const double mom[6] = {s.momentum.linear.x(),  s.momentum.linear.y(),  s.momentum.linear.z(),
                         s.momentum.angular.x(), s.momentum.angular.y(), s.momentum.angular.z()};
  write_row("momentum", rows_, mom);
  write_row("centre_of_mass", rows_, s.momentum.centre.data());
  const bool flexible_row = flexible_every_ > 0 && model_.n() > 0 && rows_ % flexible_every_ == 0;
  if (flexible_row) write_row("flexible_time", flex_rows_, &s.t);
  for (int l = 0; l < static_cast<int>(model_.links.size()); ++l) {
    const MountedLink& L = model_.links[l];
    const std::string g = "links/" + L.name + "/";
    const Vec6 tip = tip_motion(model_, l, s.q);
    write_row(g + "tip", rows_, tip.data());
    const Vec3 p = tip_position(model_, l, s.q);
    write_row(g + "tip_position", rows_, p.data());
    const Eigen::Vector3d u = tip_deflection(model_, l, s.q);
    write_row(g + "tip_deflection", rows_, u.data());
    if (!L.d.payloads.empty()) {
      std::vector<double> flat;
      for (const Payload& pl : L.d.payloads) {
        const Vec3 x = point_position(model_, l, pl.at, s.q);
        flat.insert(flat.end(), {x[0], x[1], x[2]});
      }
      write_row(g + "payload_position", rows_, flat.data());
    }
    if (flexible_row && L.n() > 0) {
      VecX ql(6 * L.n());
      for (int k = 0; k < L.n(); ++k) ql.segment<6>(6 * k) = s.q.segment<6>(model_.rfe_index(l, k));
      write_row(g + "flexible_q", flex_rows_, ql.data());
    }
  }
  if (flexible_row) ++flex_rows_;
  ++rows_;
  // Flush at most twice a second: output must not dominate a run, yet little is lost on a crash
  // and a watching reader sees the run advance.
  if (std::chrono::steady_clock::now() - last_flush_ > std::chrono::milliseconds(500)) flush();
}

void RunGroup::attribute(const std::string& key, const std::string& value) { file_.attribute(name_, key, value); }
void RunGroup::attribute(const std::string& key, double value) { file_.attribute(name_, key, value); }
void RunGroup::attribute(const std::string& key, long value) { file_.attribute(name_, key, value); }
void RunGroup::flush() {
  if (group_ < 0) return;
  if (file_.swmr())
    for (auto& [k, s] : series_) H5Dflush(s.dset);
  if (status_ >= 0 && file_.swmr()) H5Dflush(status_);
  file_.flush();
  last_flush_ = std::chrono::steady_clock::now();
}

}  // namespace rfem::app
