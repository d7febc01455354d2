// Format dispatch for point clouds: PLY (io) or LAS (las), by content.
#include "lodrefine/cloud.h"

#include <cstring>
#include <fstream>

#include "lodrefine/io.h"
#include "lodrefine/las.h"

namespace lodrefine {
namespace {

// What a file that is not a cloud looks like, for the message (the first bytes, whitespace
// skipped): XML (CityGML), JSON (CityJSON), OBJ; empty when unknown.
std::string what_else(const std::string& head) {
  const auto b = head.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return {};
  const std::string s = head.substr(b);
  if (s.rfind("<?xml", 0) == 0 || s[0] == '<') return "XML (a CityGML model?)";
  if (s[0] == '{' || s[0] == '[') return "JSON (a CityJSON model?)";
  if (s.rfind("v ", 0) == 0 || s.rfind("o ", 0) == 0 || s.rfind("# ", 0) == 0 || s.rfind("g ", 0) == 0)
    return "an OBJ model?";
  return {};
}

}  // namespace

CloudFormat cloud_format(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[64] = {};
  if (in) in.read(head, sizeof head);
  const std::string h(head, std::size_t(in ? sizeof head : in.gcount()));
  if (h.rfind("LASF", 0) == 0) return CloudFormat::Las;
  if (!in.is_open() || h.rfind("ply", 0) == 0) return CloudFormat::Ply;  // the PLY reader reports the fault
  const std::string other = what_else(h);
  if (!other.empty()) throw InputError(path + ": not a PLY or LAS point cloud: the file is " + other);
  return CloudFormat::Ply;  // unknown content: the PLY reader says "not a PLY file"
}

std::uint64_t cloud_point_count(const std::string& path) {
  return cloud_format(path) == CloudFormat::Las ? read_las_header(path).point_count : ply_vertex_count(path);
}

void stream_cloud(const std::string& path, const CloudOptions& options,
                  const std::function<void(const Vec3&)>& on_point) {
  if (cloud_format(path) == CloudFormat::Las) {
    stream_las(path, options.classes, on_point);
    return;
  }
  if (!options.classes.empty())
    throw InputError(path + ": a PLY cloud has no classification; --classes needs a LAS cloud");
  stream_ply(path, on_point);
}

PointCloud read_cloud(const std::string& path, const CloudOptions& options) {
  PointCloud cloud;
  // The declared count is bounded by the file size (checked in the header); with a class
  // filter most points may be dropped, so the vector grows instead.
  if (options.classes.empty()) cloud.points.reserve(cloud_point_count(path));
  stream_cloud(path, options, [&](const Vec3& p) { cloud.points.push_back(p); });
  return cloud;
}

std::string classes_text(const std::vector<int>& classes) {
  std::string s;
  for (int c : classes) s += (s.empty() ? "" : ",") + std::to_string(c);
  return s;
}

}  // namespace lodrefine
