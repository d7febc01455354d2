// LASzip's pointwise compressor (compressor 2, point formats 0-5) as the decoder reads it
// (src/laz/laz_pointwise.cpp): chunks of one point make no BYTE models, so many extra bytes cost
// no memory per chunk.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <string>

#include "lodrefine/formats/las.h"
#include "lodrefine/laz/laz_write.h"
#include "support/io_fixtures.h"

using namespace lodrefine;

namespace {

using fixtures::poke;
using fixtures::temp_path;

}  // namespace

namespace {

// Resident memory of this process (kB).
long resident_kb() {
  std::ifstream statm("/proc/self/statm");
  long size = 0, resident = 0;
  statm >> size >> resident;
  return resident * (::sysconf(_SC_PAGESIZE) / 1024);
}

}  // namespace

// BYTE v2 models are made on a chunk's second point: 40 chunks of one point with 65,000 extra
// bytes each made 65,000 models (130 MB) per chunk, 272 MB peak for 40 points. Read in a child
// whose peak resident memory is measured.
TEST(Laz, OnePointChunksOfManyExtraBytesMakeNoModels) {
  constexpr std::uint32_t kExtra = 65000;
  const std::string path = temp_path("one_point_chunks.laz");
  {
    LasRecordFormat f;
    f.point_format = 0, f.record_length = 20 + kExtra;
    LasRecordWriter w(path, f, true, 1);
    std::string r(20 + kExtra, '\0');
    for (int k = 0; k < 40; ++k) {
      poke<std::int32_t>(r, 0, k);
      r[20 + std::size_t(k)] = char(k);
      w.add(reinterpret_cast<const unsigned char*>(r.data()));
    }
    w.finish();
  }
  const long before = resident_kb();
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::size_t n = 0;
    stream_las_records(path, [&](const LasHeader&, const unsigned char*) { ++n; });
    ::_exit(n == 40 ? 0 : 1);
  }
  int status = 0;
  struct rusage usage {};
  ASSERT_EQ(::wait4(child, &status, 0, &usage), child);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  EXPECT_LT(usage.ru_maxrss - before, 64 * 1024) << "peak " << usage.ru_maxrss << " kB, " << before << " kB before";
}
