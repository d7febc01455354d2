// A CityJSON 1.0 / 1.1 document made 2.0 in place, as the city refine writes it (cityfile.cpp).
// Internal to city.
#pragma once
#include <nlohmann/json.hpp>

namespace lodrefine {

// CityJSON 1.0 / 1.1 objects as 2.0 wants them: "lod" a string (1.0 wrote numbers), the
// GenericCityObject extension type now core. A 2.0 input is not touched.
void upgrade_objects(nlohmann::ordered_json& objects);

// The 1.x header fields 2.0 changed: the CRS as a URL, a point of contact's address an object.
void upgrade_header(nlohmann::ordered_json& doc);

// CityJSON 1.x without a transform: 2.0 needs integer vertices, so one is made (0.1 mm).
void ensure_transform(nlohmann::ordered_json& doc);

}  // namespace lodrefine
