#include "xdmf.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "errors.hpp"
#include "reader.hpp"

namespace rfem {

namespace {

namespace fs = std::filesystem;

// One row (`row`) of the table `dataset` [rows × width·points] as points × width values.
std::string row_item(const std::string& h5, const std::string& dataset, long rows, long points, long row, int width = 3) {
  std::ostringstream o;
  o << "<DataItem ItemType=\"HyperSlab\" Dimensions=\"" << points << " " << width << "\" Type=\"HyperSlab\" NumberType=\"Float\" Precision=\"8\">"
    << "<DataItem Dimensions=\"3 2\" NumberType=\"Int\" Format=\"XML\">" << row << " 0 1 1 1 " << width * points << "</DataItem>"
    << "<DataItem Dimensions=\"" << rows << " " << width * points << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">"
    << h5 << ":/" << dataset << "</DataItem></DataItem>";
  return o.str();
}

std::string polyline(long points) {
  std::ostringstream o;
  o << "<Topology TopologyType=\"Polyline\" NumberOfElements=\"1\" NodesPerElement=\"" << points
    << "\"><DataItem Dimensions=\"1 " << points << "\" NumberType=\"Int\" Format=\"XML\">";
  for (long k = 0; k < points; ++k) o << (k ? " " : "") << k;
  o << "</DataItem></Topology>";
  return o.str();
}

std::string write_run(const ResultsReader& in, const std::string& run, const fs::path& out) {
  const std::string h5 = fs::path(in.path()).filename().string();
  const Table time = in.table(run + "/flexible_time");
  // (plain variables, not structured bindings: clang 14 cannot capture those in the lambdas below)
  const std::pair<long, long> base_shape = in.has(run + "/joint_position") ? in.shape(run + "/joint_position") : std::pair<long, long>{0, 0};
  const long rows_out = base_shape.first, m3 = base_shape.second;
  // The output row of each flexible row: the one at the same time (both series are written together).
  const std::vector<double> t_out = in.table(run + "/time").column(0);
  std::vector<long> at(static_cast<size_t>(time.rows), 0);
  for (long k = 0, i = 0; k < time.rows; ++k) {
    while (i + 1 < static_cast<long>(t_out.size()) && t_out[static_cast<size_t>(i)] < time.at(k, 0)) ++i;
    at[static_cast<size_t>(k)] = i;
  }
  struct Line {
    std::string name, position, deflection, rotation_name;
    long rows, points;
    bool rotation;
  };
  std::vector<Line> links;
  for (const std::string& l : in.children(run + "/links")) {
    const std::string g = run + "/links/" + l + "/";
    if (!in.has(g + "axis_position")) continue;
    const auto [r, c] = in.shape(g + "axis_position");
    links.push_back({l, g + "axis_position", g + "axis_deflection", g + "axis_rotation", r, c / 3, in.has(g + "axis_rotation")});
  }
  if (links.empty())
    throw ResultsError(in.path() + ": " + run + ": no stored poses (run with simulation.store_flexible_every > 0)");
  std::ostringstream x;
  x.precision(17);
  x << "<?xml version=\"1.0\" ?>\n<!-- rfem: the arm of run '" << run << "' of " << h5
    << " (docs/results.md, \"ParaView\") -->\n<Xdmf Version=\"2.0\">\n<Domain>\n";
  auto temporal = [&](const std::string& name, auto&& grid) {
    x << "<Grid Name=\"" << name << "\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (long k = 0; k < time.rows; ++k) {
      x << "<Grid Name=\"" << name << "_" << k << "\" GridType=\"Uniform\"><Time Value=\"" << time.at(k, 0) << "\"/>";
      grid(k);
      x << "</Grid>\n";
    }
    x << "</Grid>\n";
  };
  for (const Line& L : links)
    temporal(L.name, [&](long k) {
      x << polyline(L.points) << "<Geometry GeometryType=\"XYZ\">" << row_item(h5, L.position, L.rows, L.points, std::min(k, L.rows - 1))
        << "</Geometry><Attribute Name=\"deflection\" AttributeType=\"Vector\" Center=\"Node\">"
        << row_item(h5, L.deflection, L.rows, L.points, std::min(k, L.rows - 1)) << "</Attribute>";
      if (L.rotation)  // each station's body frame: ParaView's "Tensor Glyph" draws its axes
        x << "<Attribute Name=\"frame\" AttributeType=\"Tensor\" Center=\"Node\">"
          << row_item(h5, L.rotation_name, L.rows, L.points, std::min(k, L.rows - 1), 9) << "</Attribute>";
    });
  if (m3 > 0)  // the base: a polyline through the joint origins
    temporal("base", [&](long k) {
      x << polyline(m3 / 3) << "<Geometry GeometryType=\"XYZ\">"
        << row_item(h5, run + "/joint_position", rows_out, m3 / 3, std::min(at[static_cast<size_t>(k)], rows_out - 1)) << "</Geometry>";
    });
  for (const Line& L : links) {
    const std::string p = run + "/links/" + L.name + "/payload_position";
    if (!in.has(p)) continue;
    const std::pair<long, long> shape = in.shape(p);
    const long r = shape.first, c = shape.second;
    temporal(L.name + "_payloads", [&](long k) {
      x << "<Topology TopologyType=\"Polyvertex\" NumberOfElements=\"" << c / 3 << "\"/><Geometry GeometryType=\"XYZ\">"
        << row_item(h5, p, r, c / 3, std::min(at[static_cast<size_t>(k)], r - 1)) << "</Geometry>";
    });
  }
  x << "</Domain>\n</Xdmf>\n";
  // Written whole or not at all: a temporary file renamed into place.
  const fs::path tmp = out.string() + ".tmp";
  {
    std::ofstream f(tmp);
    f << x.str();
    f.close();
    if (!f) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw ResultsError(out.string() + ": cannot write");
    }
  }
  std::error_code ec;
  fs::rename(tmp, out, ec);
  if (ec) throw ResultsError(out.string() + ": cannot write: " + ec.message());
  return out.string();
}

}  // namespace

std::vector<std::string> write_xdmf(const std::string& results, const std::vector<std::string>& runs) {
  const ResultsReader in(results);
  std::vector<std::string> names = runs;
  if (names.empty()) {
    for (const std::string& g : in.children("/"))
      if (in.has(g + "/flexible_time")) names.push_back(g);
    if (names.empty())
      throw ResultsError(results + ": no run stores poses (run with simulation.store_flexible_every > 0)");
  }
  const fs::path p(results);
  std::vector<std::string> out;
  for (const std::string& run : names) {
    if (!in.has(run)) throw ResultsError(results + ": no run '" + run + "'");
    if (!in.has(run + "/flexible_time"))
      throw ResultsError(results + ": " + run + ": no stored poses (run with simulation.store_flexible_every > 0)");
    fs::path o = p;
    o.replace_extension();
    out.push_back(write_run(in, run, o.string() + "." + run + ".xdmf"));
  }
  return out;
}

}  // namespace rfem
