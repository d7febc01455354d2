// A run folder for the eval tests (RUN/<id>/{coarse.obj, cloud.ply, refined.obj, report.json}):
// a georeferenced 12 × 8 × 6 m box whose front wall (y = 0) the scan sees 0.4 m further out.
#pragma once
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "lodrefine/formats/obj.h"
#include "lodrefine/formats/ply.h"
#include "support/mesh_fixtures.h"
#include "support/scan_fixtures.h"

namespace lodrefine::fixtures {

inline const Vec3 kRunOrigin{85000.0, 447000.0, 0.0};
constexpr double kRunWallOffset = 0.4;  // m the scanned front wall lies in front of the coarse one

// A refine report of the current version: `outcome`, its reason and one moved facade (input
// faces {2}, max_move -kRunWallOffset) when refined.
inline nlohmann::json run_report(const std::string& outcome, const std::string& reason = "") {
  nlohmann::json r = {{"report_version", 1},
                      {"outcome", outcome},
                      {"reason", reason},
                      {"seconds", {{"total", 1.25}}},
                      {"selection", {{"status", "optimal"}}}};
  r["facades"] = nlohmann::json::array();
  if (outcome == "refined")
    r["facades"].push_back(
        {{"input_faces", {2}}, {"evidence", "scan"}, {"max_move", -kRunWallOffset}, {"mean_move", kRunWallOffset}});
  return r;
}

// Writes RUN/<id>/: coarse.obj and cloud.ply always; refined.obj (the box with its front wall
// on the scan) when `refined`; report.json when `report` is not null.
inline void write_run_building(const std::filesystem::path& run, const std::string& id, bool refined,
                               const nlohmann::json& report) {
  const std::filesystem::path d = run / id;
  std::filesystem::create_directories(d);
  Mesh coarse = box(Vec3(0, 0, 0), Vec3(12, 8, 6));
  write_obj((d / "coarse.obj").string(), translated(coarse, kRunOrigin));
  PointCloud scan;
  add_grid(scan, wall_patch(Vec3(0, -kRunWallOffset, 0), Vec3::UnitX(), 12.0, 0.0, 6.0), 0.1, 0.005);
  for (auto& p : scan.points) p += kRunOrigin;
  write_ply((d / "cloud.ply").string(), scan);
  if (refined)
    write_obj((d / "refined.obj").string(), translated(box(Vec3(0, -kRunWallOffset, 0), Vec3(12, 8, 6)), kRunOrigin));
  if (!report.is_null()) std::ofstream(d / "report.json") << report.dump(2);
}

}  // namespace lodrefine::fixtures
