// Internal to formats: the point-cloud readers, one row each, in the order messages name them;
// cloud.cpp dispatches every cloud file through this table. Adding a cloud format is its reader
// (include/lodrefine/formats/<format>.h, src/formats/<format>.cpp) and one row in
// cloud_readers.cpp. Its signature (the file's first bytes) stays in base's sniff_head, which
// every reader, of models too, asks to say what a file it refuses is ("the file is a PLY point
// cloud"): a new format's FileKind goes there.
#pragma once
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "lodrefine/base/files.h"
#include "lodrefine/base/types.h"

namespace lodrefine::detail {

// What a file's header declares: its points, and the points worth reserving room for before
// reading them (a count only its data can confirm is reserved up to a bound, then grows).
struct DeclaredPoints {
  std::uint64_t points = 0, reserve = 0;
};

struct CloudReader {
  FileKind kind;                   // what sniff_head finds in the file's first bytes
  std::vector<std::string> names;  // as help and messages name it ("LAS", "LAZ"); also the file name endings
  std::string magic;               // its first bytes, as a message quotes them
  bool classified;                 // its points carry classification codes (CloudOptions::classes)
  // The header, checked against the file (InputError naming it).
  DeclaredPoints (*declared)(const std::string& path);
  // Every point in file order; `classes` as CloudOptions::classes (empty for an unclassified format).
  void (*stream)(const std::string& path, const std::vector<int>& classes,
                 const std::function<void(const Vec3&)>& on_point);
};

// The rows. The first also reads what no row's signature matches, and refuses it ("not a PLY
// file").
const std::vector<CloudReader>& cloud_readers();
// The row whose signature `kind` is; nullptr for none.
const CloudReader* cloud_reader(FileKind kind);

}  // namespace lodrefine::detail
