// libFuzzer target for the case reader and the files a case reads: any byte string as a case file
// (and its first line as a --set override), optionally followed by a line "#--table--" and the
// text of `table.csv` beside it, or by "#--source--" and bytes that shape `source.h5` (the
// torque_from_run source: ranks, extents and values of its `run/time` and `run/joint_tau`), must
// yield a Case, a Model and the joints' inputs, or a CaseError: never a crash, a hang or a leak.
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include "../../cases/case_file.hpp"
#include "../../simulation/inputs.hpp"

namespace {
void write(const std::string& path, const std::string& text) {
  if (FILE* f = std::fopen(path.c_str(), "wb")) {
    std::fwrite(text.data(), 1, text.size(), f);
    std::fclose(f);
  }
}
// An HDF5 source file shaped by the bytes: per dataset a rank 1–3 and extents 0–7, then values.
void write_source(const std::string& path, const std::string& bytes) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // (the fuzzer's own process)
  size_t at = 0;
  auto byte = [&]() -> unsigned { return at < bytes.size() ? static_cast<unsigned char>(bytes[at++]) : 0u; };
  const hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (f < 0) return;
  const hid_t g = H5Gcreate2(f, "run", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  for (const char* name : {"time", "joint_tau"}) {
    const int rank = 1 + static_cast<int>(byte() % 3);
    hsize_t dims[3];
    size_t count = 1;
    for (int i = 0; i < rank; ++i) count *= (dims[i] = byte() % 8);
    std::vector<double> v(count);
    for (double& x : v) {
      unsigned char raw[8];
      for (unsigned char& b : raw) b = static_cast<unsigned char>(byte());
      std::memcpy(&x, raw, 8);  // any double: NaN, inf, denormals, out of order
    }
    const hid_t sp = H5Screate_simple(rank, dims, nullptr);
    const hid_t d = H5Dcreate2(g, name, H5T_NATIVE_DOUBLE, sp, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (d >= 0 && count > 0) H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    if (d >= 0) H5Dclose(d);
    H5Sclose(sp);
  }
  H5Gclose(g);
  H5Fclose(f);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string dir = [] {
    const std::string d = "/tmp/rfem_fuzz_" + std::to_string(getpid());
    std::filesystem::create_directories(d);
    return d;
  }();
  std::string text(reinterpret_cast<const char*>(data), size), table, source;
  for (auto [marker, part] : {std::pair<std::string, std::string*>{"\n#--source--\n", &source}, {"\n#--table--\n", &table}})
    if (const auto at = text.find(marker); at != std::string::npos) {
      *part = text.substr(at + marker.size());
      text.resize(at);
    }
  write(dir + "/case.toml", text);
  write(dir + "/table.csv", table);
  write_source(dir + "/source.h5", source);
  // The first line, if it looks like key=value, doubles as an override.
  std::vector<std::string> overrides;
  const auto nl = text.find('\n');
  if (nl != std::string::npos && nl < 80 && text.find('=') < nl) overrides.push_back(text.substr(0, nl));
  try {
    const rfem::Case c = rfem::read_case(dir + "/case.toml", overrides);
    // Keep models small: the fuzzer is after the reader, not big allocations.
    int parts = 0, n = 0;
    for (const auto& l : c.links) {
      n += l.n;
      for (const auto& s : l.link.segments) parts += s.parts;
    }
    if (n <= 64 && parts <= 64) {
      rfem::build_model(c);
      if (c.has_simulation && c.sim.options.t_end <= 1e3) rfem::joint_inputs(c);
    }
  } catch (const rfem::CaseError&) {
  }
  return 0;
}
