// CGAL's PolyFit as a baseline (polyfit_baseline.h): the points and planes lodrefine would see,
// handed to CGAL::Polygonal_surface_reconstruction as they are.
#include "lodrefine/tools/polyfit_baseline.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/GLPK_mixed_integer_program_traits.h>
#include <CGAL/Polygonal_surface_reconstruction.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/property_map.h>

#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <stdexcept>
#include <tuple>

#include "lodrefine/base/geometry.h"
#include "lodrefine/base/topology.h"
#include "lodrefine/core/distance.h"
#include "lodrefine/core/matching.h"
#include "lodrefine/core/planes.h"
#include "lodrefine/core/repair.h"
#include "lodrefine/refine/refine.h"

namespace lodrefine {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Vector = Kernel::Vector_3;
using PointWithPlane = std::tuple<Point, Vector, int>;  // PolyFit's input: point, normal, plane (-1: none)
using CgalMesh = CGAL::Surface_mesh<Point>;
using Reconstruction = CGAL::Polygonal_surface_reconstruction<Kernel>;
using GlpkTraits = CGAL::GLPK_mixed_integer_program_traits<double>;

// The points PolyFit works on and how many planes they carry.
struct PolyfitInput {
  std::vector<PointWithPlane> points;
  int planes = 0, model_planes = 0;
};

void add_point(PolyfitInput& in, const Vec3& p, const Vec3& normal, int plane) {
  in.points.emplace_back(Point(p.x(), p.y(), p.z()), Vector(normal.x(), normal.y(), normal.z()), plane);
}

// Every scan point near the model (the unassigned ones widen PolyFit's bounding box, as a
// crop's points would), with its plane's normal and index.
void add_scan(PolyfitInput& in, const PointCloud& scan, const std::vector<ScanPlane>& planes) {
  std::vector<int> plane_of(scan.points.size(), -1);
  for (std::size_t k = 0; k < planes.size(); ++k)
    for (int i : planes[k].inliers) plane_of[std::size_t(i)] = int(k);
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const int k = plane_of[i];
    add_point(in, scan.points[i], k < 0 ? Vec3::Zero() : planes[std::size_t(k)].plane.n, k < 0 ? -1 : in.planes + k);
  }
  in.planes += int(planes.size());
}

// One plane per surface of the repaired model: samples every `spacing` m and the vertices of
// its faces (at least three points off a line, so the smallest surface still fits a plane).
void add_model(PolyfitInput& in, const Mesh& local_model, const RepairConfig& params, double spacing) {
  RepairReport report;
  const Mesh mesh = merge_coplanar_faces(repair_input(local_model, params, report));
  for (const ModelSurface& s : model_surfaces(mesh)) {
    const int plane = in.planes++;
    ++in.model_planes;
    for (const Vec3& p : sample_faces(mesh, s.faces, spacing)) add_point(in, p, s.plane.n, plane);
    for (int f : s.faces)
      for (int v : mesh.faces[std::size_t(f)].v) add_point(in, mesh.vertices[std::size_t(v)], s.plane.n, plane);
  }
}

// m: CGAL computes each corner of the arrangement once per plane triple and every candidate face
// of each plane keeps its own copy, so the selected faces share corners by equal coordinates
// (to rounding), not by vertex.
constexpr double kCornerWeld = 1e-6;

// The selected faces as one mesh: corners welded, repeats and collapsed faces dropped.
Mesh welded_mesh(const CgalMesh& cm) {
  Mesh out;
  PointWelder welder(kCornerWeld);
  for (auto f : cm.faces()) {
    Face face;
    for (auto v : CGAL::vertices_around_face(cm.halfedge(f), cm)) {
      const Point& p = cm.point(v);
      face.v.push_back(welder.add(Vec3(p.x(), p.y(), p.z())));
    }
    drop_repeats(face.v);
    if (face.v.size() >= 3) out.faces.push_back(std::move(face));
  }
  out.vertices = welder.points();
  return out;
}

// Closed: every edge joins exactly two faces.
bool closed(const Mesh& mesh) {
  const EdgeUses uses = edge_uses(mesh.faces);
  return !mesh.faces.empty() &&
         std::all_of(uses.begin(), uses.end(), [](const auto& e) { return e.second.size() == 2; });
}

// PolyFit on the prepared points: arrangement, confidences, GLPK, closedness.
void reconstruct(const PolyfitInput& in, const PolyfitOptions& options, const Vec3& origin, PolyfitResult& r) {
  const Clock::time_point t0 = Clock::now();
  Reconstruction algo(in.points, CGAL::Nth_of_tuple_property_map<0, PointWithPlane>(),
                      CGAL::Nth_of_tuple_property_map<1, PointWithPlane>(),
                      CGAL::Nth_of_tuple_property_map<2, PointWithPlane>());
  if (!algo.error_message().empty()) {
    r.polyfit_seconds = seconds_since(t0);
    r.status = PolyfitStatus::TooFewPlanes, r.reason = algo.error_message();
    return;
  }
  CgalMesh candidates;
  algo.output_candidate_faces(candidates);
  r.candidates = int(candidates.number_of_faces());
  CgalMesh selected;
  const bool solved =
      algo.reconstruct<GlpkTraits>(selected, options.wt_fitting, options.wt_coverage, options.wt_complexity);
  r.polyfit_seconds = seconds_since(t0);
  if (!solved) {
    const bool too_few = algo.error_message().rfind("at least 4", 0) == 0;
    r.status = too_few ? PolyfitStatus::TooFewPlanes : PolyfitStatus::Infeasible;
    r.reason = algo.error_message();
    return;
  }
  Mesh mesh = welded_mesh(selected);
  if (mesh.faces.empty()) {
    r.status = PolyfitStatus::Empty;
    r.reason = "no face selected (an empty selection scored best, or glp_intopt returned 0 without a solution)";
    return;
  }
  const bool is_closed = closed(mesh);
  if (is_closed) orient_outward(mesh);  // PolyFit leaves each face as its plane's candidate was cut
  r.mesh = translated(std::move(mesh), origin);
  if (!is_closed) {
    r.status = PolyfitStatus::NotClosed;
    r.reason = std::to_string(r.mesh.faces.size()) + " faces selected, an edge not shared by exactly two";
    return;
  }
  r.status = PolyfitStatus::Closed;
}

void run(const Mesh& model, const PointCloud& cloud, const RefineConfig& params, const PolyfitOptions& options,
         PolyfitResult& r) {
  params.validate();
  const Vec3 origin = local_origin(model);
  const Mesh local_model = translated(model, -origin);
  if (local_model.vertices.empty()) throw InputError("the model has no vertices");
  const PointCloud scan = cloud_near(local_model, cloud, origin, params);
  const Clock::time_point t0 = Clock::now();
  const std::vector<ScanPlane> planes = detect_planes(scan, params.plane);
  r.detection_seconds = seconds_since(t0);
  PolyfitInput in;
  add_scan(in, scan, planes);
  if (options.planes == PolyfitPlanes::ModelAndScan) add_model(in, local_model, params.repair, options.model_spacing);
  r.planes = in.planes, r.model_planes = in.model_planes, r.points = in.points.size();
  reconstruct(in, options, origin, r);
}

// CPU seconds this process has used.
double process_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

// A result through the pipe from the child: plain values appended to / read from a byte string.
struct Wire {
  std::string bytes;
  std::size_t at = 0;
  template <class T>
  void put(const T& v) {
    bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put_string(const std::string& v) {
    put(v.size());
    bytes += v;
  }
  template <class T>
  T get() {  // throws InputError past the end (a child that died mid-write)
    T v{};
    if (bytes.size() - at < sizeof v) throw InputError("truncated result");
    std::memcpy(&v, bytes.data() + at, sizeof v);
    at += sizeof v;
    return v;
  }
  std::string get_string() {
    const auto n = get<std::size_t>();
    if (bytes.size() - at < n) throw InputError("truncated result");
    at += n;
    return bytes.substr(at - n, n);
  }
};

std::string encode(const PolyfitResult& r) {
  Wire w;
  w.put(int(r.status)), w.put_string(r.reason);
  w.put(r.planes), w.put(r.model_planes), w.put(r.candidates), w.put(r.points);
  w.put(r.seconds), w.put(r.detection_seconds), w.put(r.polyfit_seconds), w.put(r.cpu_seconds);
  w.put(r.mesh.vertices.size());
  for (const Vec3& v : r.mesh.vertices) w.put(v.x()), w.put(v.y()), w.put(v.z());
  w.put(r.mesh.faces.size());
  for (const Face& f : r.mesh.faces) {
    w.put(f.v.size());
    for (int v : f.v) w.put(v);
  }
  return w.bytes;
}

PolyfitResult decode(std::string bytes) {
  Wire w{std::move(bytes)};
  PolyfitResult r;
  r.status = PolyfitStatus(w.get<int>()), r.reason = w.get_string();
  r.planes = w.get<int>(), r.model_planes = w.get<int>(), r.candidates = w.get<int>();
  r.points = w.get<std::size_t>();
  r.seconds = w.get<double>(), r.detection_seconds = w.get<double>();
  r.polyfit_seconds = w.get<double>(), r.cpu_seconds = w.get<double>();
  r.mesh.vertices.resize(w.get<std::size_t>());
  for (Vec3& v : r.mesh.vertices) v.x() = w.get<double>(), v.y() = w.get<double>(), v.z() = w.get<double>();
  r.mesh.faces.resize(w.get<std::size_t>());
  for (Face& f : r.mesh.faces) {
    f.v.resize(w.get<std::size_t>());
    for (int& v : f.v) v = w.get<int>();
  }
  return r;
}

// The child: limits set, the baseline run, its result written, no return (no atexit handlers,
// no stdio buffers of the parent flushed twice).
[[noreturn]] void run_child(int out, const Mesh& model, const PointCloud& cloud, const RefineConfig& params,
                            const PolyfitOptions& options) {
  const rlim_t cpu = rlim_t(std::ceil(options.cpu_limit));
  const rlimit cpu_limit{cpu, cpu + 1};  // SIGXCPU at the soft limit, SIGKILL a second later
  const rlim_t bytes = rlim_t(options.memory_limit_mb) << 20;
  const rlimit memory_limit{bytes, bytes};
  setrlimit(RLIMIT_CPU, &cpu_limit);
  // AddressSanitizer maps terabytes of shadow memory: an address-space limit aborts it at once.
#if !defined(__SANITIZE_ADDRESS__)
  setrlimit(RLIMIT_AS, &memory_limit);
#else
  (void)memory_limit;
#endif
  PolyfitResult r = polyfit_baseline(model, cloud, params, options);
  r.cpu_seconds = process_cpu_seconds();
  const std::string bytes_out = encode(r);
  for (std::size_t done = 0; done < bytes_out.size();) {
    const ssize_t n = write(out, bytes_out.data() + done, bytes_out.size() - done);
    if (n <= 0) _exit(1);
    done += std::size_t(n);
  }
  _exit(0);
}

// Everything the child writes, until it closes the pipe or `wall_limit` seconds pass (false).
bool read_all(int in, double wall_limit, std::string& bytes) {
  const Clock::time_point t0 = Clock::now();
  char buf[1 << 16];
  for (;;) {
    const double left = wall_limit - seconds_since(t0);
    if (left <= 0) return false;
    pollfd p{in, POLLIN, 0};
    const int ready = poll(&p, 1, int(std::min(left, 1.0) * 1000) + 1);
    if (ready < 0 && errno != EINTR) return false;
    if (ready <= 0) continue;
    const ssize_t n = read(in, buf, sizeof buf);
    if (n == 0) return true;
    if (n < 0 && errno != EINTR) return false;
    if (n > 0) bytes.append(buf, std::size_t(n));
  }
}

// The child's result, or what its end says (limit, signal, nothing written).
PolyfitResult child_result(int status, bool in_time, std::string bytes, const PolyfitOptions& options) {
  PolyfitResult r;
  const bool killed = WIFSIGNALED(status);
  const int sig = killed ? WTERMSIG(status) : 0;
  if (!in_time || sig == SIGXCPU || sig == SIGKILL) {
    r.status = PolyfitStatus::TimeLimit;
    r.reason = "over the limit of " + std::to_string(int(options.cpu_limit)) + " s CPU";
    r.cpu_seconds = options.cpu_limit;  // at least
  } else if (killed) {
    r.status = PolyfitStatus::Error;
    r.reason = "ended by signal " + std::to_string(sig) + " (" + strsignal(sig) + ")";
  } else {
    try {
      return decode(std::move(bytes));
    } catch (const InputError&) {
      r.status = PolyfitStatus::Error;
      r.reason = "the child process exited with status " + std::to_string(WEXITSTATUS(status)) + " and no result";
    }
  }
  return r;
}

}  // namespace

const char* polyfit_planes_name(PolyfitPlanes planes) { return planes == PolyfitPlanes::Scan ? "scan" : "model+scan"; }

const char* polyfit_status_name(PolyfitStatus status) {
  switch (status) {
    case PolyfitStatus::Closed: return "closed";
    case PolyfitStatus::NotClosed: return "not-closed";
    case PolyfitStatus::Empty: return "empty";
    case PolyfitStatus::Infeasible: return "infeasible";
    case PolyfitStatus::TooFewPlanes: return "too-few-planes";
    case PolyfitStatus::TimeLimit: return "time-limit";
    case PolyfitStatus::Error: return "error";
  }
  return "?";
}

PolyfitResult polyfit_baseline(const Mesh& model, const PointCloud& cloud, const RefineConfig& params,
                               const PolyfitOptions& options) {
  const Clock::time_point t0 = Clock::now();
  PolyfitResult r;
  try {
    run(model, cloud, params, options, r);
  } catch (const std::exception& e) {  // InputError, CGAL's failures, bad_alloc: a failure, never a crash
    r = PolyfitResult{};
    r.status = PolyfitStatus::Error;
    r.reason = e.what();
  }
  r.seconds = seconds_since(t0);
  return r;
}

PolyfitResult polyfit_baseline_isolated(const Mesh& model, const PointCloud& cloud, const RefineConfig& params,
                                        const PolyfitOptions& options) {
  const Clock::time_point t0 = Clock::now();
  int fds[2];
  if (pipe(fds) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  std::fflush(nullptr);
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]), close(fds[1]);
    throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  }
  if (pid == 0) {
    close(fds[0]);
    run_child(fds[1], model, cloud, params, options);
  }
  close(fds[1]);
  std::string bytes;
  // Wall time guards a child that sleeps or starves: 10x its CPU limit (a loaded machine).
  const bool in_time = read_all(fds[0], 10.0 * options.cpu_limit + 10.0, bytes);
  close(fds[0]);
  if (!in_time) kill(pid, SIGKILL);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  PolyfitResult r = child_result(status, in_time, std::move(bytes), options);
  if (r.status == PolyfitStatus::TimeLimit || r.seconds == 0) r.seconds = seconds_since(t0);
  return r;
}

}  // namespace lodrefine
