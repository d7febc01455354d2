// Reading LoD2 buildings from CityGML 1.0 / 2.0 (through libcitygml) into the same structure
// the CityJSON reader produces, and reading either kind of city file by its content.
//
// Every Building and BuildingPart with LoD2 geometry becomes one Mesh (id = its gml:id; parts
// are not merged into their parent). The faces come from its thematic boundary surfaces
// (bldg:boundedBy Wall/Roof/GroundSurface ..., with their semantics) when it has any, else
// from its lod2Solid / lod2MultiSurface (semantics Other). Polygons referenced twice (a solid
// xlinking its boundary surfaces) are taken once; inner rings are dropped and counted, as in
// the CityJSON reader. The CRS is the file's first srsName, written as a CityJSON
// referenceSystem URL when it names an EPSG code.
#pragma once
#include <string>
#include <vector>

#include "lodrefine/formats/cityjson.h"

namespace lodrefine {

// Throws InputError "<path>: <fault>" (one line) for unreadable files, non-CityGML content,
// CityGML 3.0 (libcitygml reads 1.0 and 2.0) and files libcitygml cannot parse; and, before
// libcitygml reads anything, files with a DTD or entity declaration (<!DOCTYPE: external
// entities, URL fetches, entity expansion) or in an encoding other than UTF-8, US-ASCII or
// ISO-8859-1. Nothing is fetched over the network (no DTD, no schema is loaded). Text with
// entity or character references comes through whole ("Bakery &amp; Sons" -> "Bakery & Sons").
CityJsonFile read_citygml(const std::string& path);

// The buildings of a CityGML file as a CityJSON 2.0 document (what read_citygml reads):
// Building / BuildingPart objects with parents/children, attributes, one LoD 2 MultiSurface
// with semantics, the CRS as metadata.referenceSystem, vertices at kCityGmlResolution.
// `citygml_version` gets "1.0" or "2.0". Object ids are the gml:ids; every building and part
// keeps one of its own: a gml:id given twice is written as "<id>~2" the second time (`notes`
// gets a line naming both), an object without a gml:id becomes "building-<n>", never an id
// the file gives another object.
nlohmann::ordered_json citygml_to_cityjson(const std::string& path, std::string* citygml_version = nullptr,
                                           std::vector<std::string>* notes = nullptr);

// A CityJSON / CityJSONSeq or CityGML file, chosen by content (XML: CityGML).
CityJsonFile read_city_file(const std::string& path);

// "urn:ogc:def:crs:EPSG::28992", "EPSG:28992", ... -> "https://www.opengis.net/def/crs/EPSG/0/28992";
// other names, and names longer than kMaxCrsName bytes, are returned unchanged.
inline constexpr std::size_t kMaxCrsName = 200;
std::string crs_url(const std::string& srs_name);

}  // namespace lodrefine
