// Building models as OBJ polygon soups (the per-building CityGML export). The reader throws
// InputError with a one-line message on malformed input; the writer is atomic.
#pragma once
#include <string>
#include <vector>

#include "lodrefine/base/files.h"
#include "lodrefine/base/types.h"

namespace lodrefine {

// Reads an OBJ polygon soup as exported per building from CityGML: `g WallSurface` /
// `g RoofSurface` / `g GroundSurface` groups (also `usemtl`), polygons of 3+ vertices,
// georeferenced doubles. Building id from `o NAME`, else a `# id: X` comment, else the file
// stem. Faces are kept as given (no welding); Face::source is the face's index in the file, and
// Face::provenance the one a group names (`g WallSurface scan`: provenance_from_group).
Mesh read_obj(const std::string& path);
// Same, also reporting how many `f` statements with fewer than 3 vertices were skipped (they
// are no polygons and get no Face::source number; the file is rejected only when no face
// remains). Positive indices may refer to vertices defined later in the file; negative ones
// are relative to the vertices so far.
Mesh read_obj(const std::string& path, int* skipped_faces);

// The group a repaired building's fins are written in, after the solid's faces (`g fins
// WallSurface`, `g fins RoofSurface`, ...: each fin also in its semantic's group). A face in a
// group of this name (any name of its `g` line, exactly) is a fin.
inline constexpr const char* kFinsGroup = "fins";

// A building's OBJ with its fins told apart.
struct ObjModel {
  Mesh solid;  // every face outside a fins group (a repaired building's solid), in file order
  Mesh fins;   // the faces of fins groups, in file order (none in most files)
};
// Reads as read_obj does (the same refusals; both meshes carry the id, each only the vertices
// its faces use). `solid` may be empty when every face is in a fins group: callers that need a
// solid say so.
ObjModel read_obj_model(const std::string& path);
// read_obj, also telling fins apart: `in_fins` gets one flag per face of the result, set for a
// face in a fins group (the mesh as one soup, for refine; split_fins parts it as read).
Mesh read_obj(const std::string& path, std::vector<char>& in_fins);
// `mesh`'s faces flagged in `in_fins` (one flag per face) apart from the others, in order, each
// part with only the vertices its faces use and the mesh's id.
ObjModel split_fins(const Mesh& mesh, const std::vector<char>& in_fins);

// Writes polygons grouped by semantic (`g WallSurface` ...) and provenance (`g WallSurface scan`,
// `g RoofSurface model`, `g WallSurface added`; a face without one in its semantic's plain group),
// each scan face after a `# lodrefine_coverage 0.85` comment (Face::coverage), `o <id>`, vertices offset by
// `origin` (the local frame's origin) and printed with enough digits for < 0.1 mm at 7-digit
// magnitudes. Atomic (temp + rename). Throws std::runtime_error if the target is not writable.
void write_obj(const std::string& path, const Mesh& mesh, const Vec3& origin = Vec3::Zero());
// The same with `fins` (faces no solid holds, beside a repaired building's solid) after the
// mesh's faces, in groups `g fins <semantic>` (kFinsGroup; with their provenance word as the
// solid's: `g fins WallSurface model`), so that readers tell them apart.
void write_obj(const std::string& path, const Mesh& mesh, const Mesh& fins, const Vec3& origin = Vec3::Zero());

}  // namespace lodrefine
