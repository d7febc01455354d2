// Validating every building of a city file under val3dity's error codes (`lodrefine validate`),
// and the report shaped like val3dity's.
#pragma once
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "lodrefine/core/validate.h"

namespace lodrefine {

struct BuildingValidity {
  std::string id;
  std::string type;           // "Building" or "BuildingPart"
  std::string lod;            // the LoD of the geometry validated, as the file writes it
  std::string geometry_type;  // "Solid", "MultiSurface", ... (CityGML: "Solid" or "MultiSurface")
  Validation validation;      // validate_soup's, plus 101 for rings the reader dropped
  bool valid() const { return validation.errors.empty(); }
};

struct CityValidity {
  std::string path;
  std::string input_format;  // "CityJSON 2.0", "CityJSONSeq 2.0", "CityGML 2.0"
  ValidityTolerances tolerances;
  std::vector<BuildingValidity> buildings;   // in file order
  std::vector<std::string> ids_without_lod;  // Building/BuildingPart objects without the LoD asked for
  int invalid() const;
};

// Reads the city file at `path` (CityJSON 1.0-2.0, CityJSONSeq, CityGML 1.0/2.0) and validates
// each Building and BuildingPart's geometry of LoD `lod` ("" = the highest 2.x; CityGML: LoD 2
// only) as one solid (validate_soup). A ring the reader drops (fewer than 3 distinct vertices)
// is a 101. Throws InputError, one line, when the file cannot be read or holds no building with
// that LoD.
CityValidity validate_city(const std::string& path, const std::string& lod, const ValidityTolerances& tolerances);

// The report in val3dity's shape: type "val3dity_report", generator ("lodrefine <version>"),
// input_file, input_file_type, parameters (snap_tol, planarity_d2p_tol), features_overview and
// primitives_overview ({type, total, valid}), features (one per building: id, type, validity,
// errors as validity_errors_json writes them, lod, geometry_type), dataset_errors (empty),
// all_errors (the codes found, ascending) and validity. No time: the same file gives the same
// report.
nlohmann::json validity_report_json(const CityValidity& city);

// "302 SHELL_NOT_CLOSED (4 boundary edges (mesh not closed)); 305 ...": the errors on one line.
std::string errors_text(const std::vector<ValidityError>& errors);

}  // namespace lodrefine
