// SPDX-License-Identifier: GPL-3.0-or-later
#include "peers.h"

#include "child_process.h"
#include "tool_support.h"

#include <pcl_ms/reconstruct.h>

#include <CGAL/Advancing_front_surface_reconstruction.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/compute_average_spacing.h>
#include <CGAL/mst_orient_normals.h>
#include <CGAL/property_map.h>

#include <pcl/console/print.h>
#include <pcl/conversions.h>
#include <pcl/features/normal_3d.h>
#include <pcl/search/kdtree.h>
#include <pcl/surface/gp3.h>
#include <pcl/surface/poisson.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace pcl_ms_tools {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalPoint = Kernel::Point_3;
using CgalVector = Kernel::Vector_3;

/// PoissonRecon inside PCL and CGAL's advancing front print internal
/// messages with printf / std::cerr; the tools report one line of their own.
class SilenceStandardStreams {
public:
  SilenceStandardStreams() {
    std::fflush(nullptr);
    const int null = open("/dev/null", O_WRONLY);
    for (int k = 0; k < 2; ++k) {
      saved_[k] = dup(kStreams[k]);
      if (saved_[k] >= 0 && null >= 0)
        dup2(null, kStreams[k]);
    }
    if (null >= 0)
      close(null);
  }
  ~SilenceStandardStreams() {
    std::fflush(nullptr);
    for (int k = 0; k < 2; ++k)
      if (saved_[k] >= 0) {
        dup2(saved_[k], kStreams[k]);
        close(saved_[k]);
      }
  }
  SilenceStandardStreams(const SilenceStandardStreams &) = delete;
  SilenceStandardStreams &operator=(const SilenceStandardStreams &) = delete;

private:
  static constexpr int kStreams[2] = {STDOUT_FILENO, STDERR_FILENO};
  int saved_[2] = {-1, -1};
};

/// Times consecutive stages of one run and announces each as it starts.
class Stages {
public:
  Stages(PeerRun &run, const StageCallback &on_stage) : run_(run), on_stage_(on_stage) {}
  void start(const std::string &name) {
    stop();
    if (on_stage_)
      on_stage_(name);
    run_.stages.push_back({name, 0});
    start_ = std::chrono::steady_clock::now();
    running_ = true;
  }
  void stop() {
    if (running_)
      run_.stages.back().seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    running_ = false;
  }

private:
  PeerRun &run_;
  const StageCallback &on_stage_;
  std::chrono::steady_clock::time_point start_;
  bool running_ = false;
};

std::vector<CgalPoint> toCgal(const pcl::PointCloud<pcl::PointXYZ> &points) {
  std::vector<CgalPoint> result;
  result.reserve(points.size());
  for (const pcl::PointXYZ &p : points)
    result.emplace_back(p.x, p.y, p.z);
  return result;
}

std::string formatNumber(double value) {
  std::ostringstream out;
  out.precision(4);
  out << value;
  return out.str();
}

/// Normals as in PCL's tutorials (NormalEstimation, k nearest neighbours in a
/// kd-tree), then oriented consistently by propagation along a minimum
/// spanning tree of the k-NN graph (CGAL's mst_orient_normals, Hoppe et
/// al. 1992), seeded at the point of largest z with its normal turned to +z,
/// which is outwards there on a closed surface. PCL's tutorials flip
/// normals towards a viewpoint, which turns half of a closed object inside
/// out. Returns the points with normals and says what could not be done.
pcl::PointCloud<pcl::PointNormal>::Ptr orientedNormals(const pcl::PointCloud<pcl::PointXYZ> &points,
                                                       const PeerSettings &settings, Stages &stages,
                                                       std::string &note) {
  stages.start("normals");
  auto input = pcl::make_shared<pcl::PointCloud<pcl::PointXYZ>>(points);
  pcl::PointCloud<pcl::Normal> normals;
  {
    SilencePclMessages silence;
    pcl::NormalEstimation<pcl::PointXYZ, pcl::Normal> estimation;
    estimation.setInputCloud(input);
    estimation.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
    estimation.setKSearch(settings.normal_neighbours);
    estimation.compute(normals);
  }
  if (normals.size() != points.size())
    throw std::runtime_error("normal estimation failed");

  stages.start("orientation");
  // Index, position, normal: mst_orient_normals reorders its range.
  using Record = std::tuple<std::size_t, CgalPoint, CgalVector>;
  std::vector<Record> records;
  records.reserve(points.size());
  std::size_t undefined = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const pcl::Normal &n = normals[i];
    CgalVector normal(n.normal_x, n.normal_y, n.normal_z);
    if (!std::isfinite(n.normal_x) || !std::isfinite(n.normal_y) || !std::isfinite(n.normal_z)) {
      normal = CgalVector(0, 0, 1); // too few distinct neighbours for a plane
      ++undefined;
    }
    records.emplace_back(i, CgalPoint(points[i].x, points[i].y, points[i].z), normal);
  }
  std::size_t unoriented = 0;
  if (records.size() >= 3) {
    const auto first_unoriented = CGAL::mst_orient_normals(
        records, static_cast<unsigned int>(std::max(settings.normal_neighbours, 2)),
        CGAL::parameters::point_map(CGAL::Nth_of_tuple_property_map<1, Record>())
            .normal_map(CGAL::Nth_of_tuple_property_map<2, Record>()));
    unoriented = static_cast<std::size_t>(std::distance(first_unoriented, records.end()));
  }
  auto result = pcl::make_shared<pcl::PointCloud<pcl::PointNormal>>();
  result->resize(points.size());
  for (const Record &record : records) {
    pcl::PointNormal &p = (*result)[std::get<0>(record)];
    p.x = static_cast<float>(std::get<1>(record).x());
    p.y = static_cast<float>(std::get<1>(record).y());
    p.z = static_cast<float>(std::get<1>(record).z());
    p.normal_x = static_cast<float>(std::get<2>(record).x());
    p.normal_y = static_cast<float>(std::get<2>(record).y());
    p.normal_z = static_cast<float>(std::get<2>(record).z());
    p.curvature = normals[std::get<0>(record)].curvature;
  }
  note = "normals from " + std::to_string(settings.normal_neighbours) + " neighbours, MST-oriented";
  if (unoriented > 0)
    note += " (" + std::to_string(unoriented) + " left as estimated)";
  if (undefined > 0)
    note += " (" + std::to_string(undefined) + " undefined, set to +z)";
  return result;
}

void takePolygons(const std::vector<pcl::Vertices> &polygons, std::vector<pcl_ms::Triangle> &out) {
  out.clear();
  out.reserve(polygons.size());
  for (const pcl::Vertices &polygon : polygons) {
    const auto &v = polygon.vertices;
    for (std::size_t k = 1; k + 1 < v.size(); ++k) // fan over polygons with more corners
      out.push_back({static_cast<pcl_ms::VertexIndex>(v[0]), static_cast<pcl_ms::VertexIndex>(v[k]),
                     static_cast<pcl_ms::VertexIndex>(v[k + 1])});
  }
}

void runPclMs(const pcl::PointCloud<pcl::PointXYZ> &points, const PeerSettings &settings,
              Stages &stages, PeerRun &run) {
  const pcl_ms::PointView view = pointView(points);
  pcl_ms::Parameters parameters; // the library's defaults
  parameters.num_threads = settings.threads;
  parameters.viewpoint = settings.viewpoint;
  parameters.allow_non_manifold = settings.non_manifold;
  stages.start("reconstruction");
  pcl_ms::Result result = pcl_ms::reconstruct(view, parameters);
  stages.stop();
  // The core times its own stages; report those instead of the one call.
  const pcl_ms::StageTimings &t = result.timings;
  run.stages = {{"prepare", t.prepare},
                {"delaunay", t.delaunay},
                {"scaffold", t.scaffold},
                {"greedy", t.greedy},
                {"finish", t.finish}};
  run.triangles = std::move(result.triangles);
  run.configuration = "defaults (rho " + formatNumber(parameters.rho) + ", fill holes up to " +
                      std::to_string(parameters.fill_holes_max_edges) + " edges), no normals";
  if (parameters.allow_non_manifold)
    run.configuration += ", non-manifold seams allowed";
  if (parameters.viewpoint)
    run.configuration += ", viewpoint " + formatNumber((*parameters.viewpoint)[0]) + "," +
                         formatNumber((*parameters.viewpoint)[1]) + "," +
                         formatNumber((*parameters.viewpoint)[2]) + " (the sensor origin)";
}

void runGp3(const pcl::PointCloud<pcl::PointXYZ> &points, const PeerSettings &settings,
            Stages &stages, PeerRun &run) {
  std::string normals_note;
  const auto cloud = orientedNormals(points, settings, stages, normals_note);

  stages.start("spacing");
  const std::vector<CgalPoint> cgal_points = toCgal(points);
  const double spacing = CGAL::compute_average_spacing<CGAL::Sequential_tag>(cgal_points, 6);
  const double radius = settings.gp3_radius_factor * spacing;
  if (!(radius > 0))
    throw std::runtime_error("the points have no spacing (all at one position?)");

  stages.start("triangulation");
  pcl::PolygonMesh mesh;
  {
    SilencePclMessages silence;
    pcl::GreedyProjectionTriangulation<pcl::PointNormal> gp3;
    gp3.setSearchRadius(radius);
    gp3.setMu(settings.gp3_mu);
    gp3.setMaximumNearestNeighbors(settings.gp3_max_nearest_neighbours);
    // PCL's GP3 tutorial values.
    gp3.setMaximumSurfaceAngle(M_PI / 4);
    gp3.setMinimumAngle(M_PI / 18);
    gp3.setMaximumAngle(2 * M_PI / 3);
    gp3.setNormalConsistency(false);
    // Not in the tutorial, whose normals are not oriented: ours are, so the
    // triangles can be wound consistently around them.
    gp3.setConsistentVertexOrdering(true);
    gp3.setInputCloud(cloud);
    gp3.setSearchMethod(pcl::make_shared<pcl::search::KdTree<pcl::PointNormal>>());
    gp3.reconstruct(mesh);
  }
  stages.stop();
  takePolygons(mesh.polygons, run.triangles);
  run.configuration = normals_note + "; search radius " + formatNumber(radius) + " (" +
                      formatNumber(settings.gp3_radius_factor) + " x spacing " +
                      formatNumber(spacing) + "), mu " + formatNumber(settings.gp3_mu) +
                      ", at most " + std::to_string(settings.gp3_max_nearest_neighbours) +
                      " neighbours";
}

void runPoisson(const pcl::PointCloud<pcl::PointXYZ> &points, const PeerSettings &settings,
                Stages &stages, PeerRun &run) {
  std::string normals_note;
  const auto cloud = orientedNormals(points, settings, stages, normals_note);
  stages.start("poisson");
  pcl::PolygonMesh mesh;
  {
    SilencePclMessages silence;
    SilenceStandardStreams silence_printf;
    pcl::Poisson<pcl::PointNormal> poisson;
    poisson.setDepth(settings.poisson_depth);
    poisson.setThreads(1); // single-threaded like the others, and reproducible
    poisson.setInputCloud(cloud);
    poisson.reconstruct(mesh);
  }
  stages.stop();
  pcl::PointCloud<pcl::PointXYZ> vertices;
  pcl::fromPCLPointCloud2(mesh.cloud, vertices);
  run.vertices.clear();
  run.vertices.reserve(vertices.size());
  for (const pcl::PointXYZ &p : vertices)
    run.vertices.emplace_back(p.x, p.y, p.z);
  run.vertices_are_input = false;
  takePolygons(mesh.polygons, run.triangles);
  run.configuration = normals_note + "; depth " + std::to_string(settings.poisson_depth) +
                      ", other parameters PCL's defaults";
}

void runAfsr(const pcl::PointCloud<pcl::PointXYZ> &points, Stages &stages, PeerRun &run) {
  const std::vector<CgalPoint> cgal_points = toCgal(points);
  std::vector<std::array<std::size_t, 3>> facets;
  stages.start("reconstruction");
  {
    SilenceStandardStreams silence;
    CGAL::advancing_front_surface_reconstruction(cgal_points.begin(), cgal_points.end(),
                                                 std::back_inserter(facets));
  }
  stages.stop();
  run.triangles.reserve(facets.size());
  for (const auto &facet : facets)
    run.triangles.push_back({static_cast<pcl_ms::VertexIndex>(facet[0]),
                             static_cast<pcl_ms::VertexIndex>(facet[1]),
                             static_cast<pcl_ms::VertexIndex>(facet[2])});
  run.configuration = "default parameters";
}

void fillInputVertices(const pcl::PointCloud<pcl::PointXYZ> &points, PeerRun &run) {
  if (!run.vertices_are_input)
    return;
  run.vertices.clear();
  run.vertices.reserve(points.size());
  for (const pcl::PointXYZ &p : points)
    run.vertices.emplace_back(p.x, p.y, p.z);
}

std::string oneLine(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  while (!text.empty() && text.back() == ' ')
    text.pop_back();
  return text.empty() ? "unknown failure" : text;
}

// --- Passing a run from the child to the parent -----------------------------

class Writer {
public:
  template <typename T> void value(const T &v) {
    bytes_.append(reinterpret_cast<const char *>(&v), sizeof(T));
  }
  void text(const std::string &s) {
    value<std::uint64_t>(s.size());
    bytes_ += s;
  }
  template <typename T> void array(const std::vector<T> &v) {
    value<std::uint64_t>(v.size());
    bytes_.append(reinterpret_cast<const char *>(v.data()), v.size() * sizeof(T));
  }
  std::string take() { return std::move(bytes_); }

private:
  std::string bytes_;
};

class Reader {
public:
  explicit Reader(const std::string &bytes) : bytes_(bytes) {}
  template <typename T> T value() {
    T v;
    need(sizeof(T));
    std::memcpy(&v, bytes_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return v;
  }
  std::string text() {
    const auto size = value<std::uint64_t>();
    need(size);
    std::string s = bytes_.substr(at_, size);
    at_ += size;
    return s;
  }
  template <typename T> std::vector<T> array() {
    const auto size = value<std::uint64_t>();
    if (size > bytes_.size() / sizeof(T))
      throw std::runtime_error("truncated result from the child process");
    std::vector<T> v(size);
    need(size * sizeof(T));
    std::memcpy(static_cast<void *>(v.data()), bytes_.data() + at_, size * sizeof(T));
    at_ += size * sizeof(T);
    return v;
  }

private:
  void need(std::size_t size) const {
    if (size > bytes_.size() - at_)
      throw std::runtime_error("truncated result from the child process");
  }
  const std::string &bytes_;
  std::size_t at_ = 0;
};

std::string serialize(const PeerRun &run) {
  Writer out;
  out.value<std::uint8_t>(run.ok);
  out.text(run.error);
  out.text(run.configuration);
  out.value(run.peak_mb);
  out.value<std::uint64_t>(run.stages.size());
  for (const StageTime &stage : run.stages) {
    out.text(stage.name);
    out.value(stage.seconds);
  }
  out.value<std::uint8_t>(run.vertices_are_input);
  if (!run.vertices_are_input)
    out.array(run.vertices);
  out.array(run.triangles);
  return out.take();
}

void deserialize(const std::string &bytes, PeerRun &run) {
  Reader in(bytes);
  run.ok = in.value<std::uint8_t>() != 0;
  run.error = in.text();
  run.configuration = in.text();
  run.peak_mb = in.value<double>();
  const auto stages = in.value<std::uint64_t>();
  run.stages.clear();
  for (std::uint64_t i = 0; i < stages && i < bytes.size(); ++i) {
    StageTime stage;
    stage.name = in.text();
    stage.seconds = in.value<double>();
    run.stages.push_back(stage);
  }
  run.vertices_are_input = in.value<std::uint8_t>() != 0;
  if (!run.vertices_are_input)
    run.vertices = in.array<Eigen::Vector3d>();
  run.triangles = in.array<pcl_ms::Triangle>();
}

/// Runs the method; input vertices are left for the caller to fill in.
PeerRun runMethod(Method method, const pcl::PointCloud<pcl::PointXYZ> &points,
                  const PeerSettings &settings, const StageCallback &on_stage) {
  PeerRun run;
  run.method = method;
  try {
    for (const pcl::PointXYZ &p : points)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw std::invalid_argument("the points must be finite");
    if (points.size() < 3)
      throw std::invalid_argument("at least 3 points are needed, got " +
                                  std::to_string(points.size()));
    Stages stages(run, on_stage);
    switch (method) {
    case Method::pcl_ms:
      runPclMs(points, settings, stages, run);
      break;
    case Method::gp3:
      runGp3(points, settings, stages, run);
      break;
    case Method::poisson:
      runPoisson(points, settings, stages, run);
      break;
    case Method::afsr:
      runAfsr(points, stages, run);
      break;
    }
    stages.stop();
    const std::size_t vertex_count = run.vertices_are_input ? points.size() : run.vertices.size();
    for (const pcl_ms::Triangle &t : run.triangles)
      if (std::max({t[0], t[1], t[2]}) >= vertex_count)
        throw std::runtime_error("a triangle indexes a missing vertex");
    run.ok = !run.triangles.empty();
    if (!run.ok)
      run.error = "no triangles";
  } catch (const std::exception &exception) {
    run.ok = false;
    run.error = oneLine(exception.what());
    run.triangles.clear();
  }
  return run;
}

} // namespace

const std::vector<Method> &allMethods() {
  static const std::vector<Method> methods = {Method::pcl_ms, Method::gp3, Method::poisson,
                                              Method::afsr};
  return methods;
}

std::string methodKey(Method method) {
  switch (method) {
  case Method::pcl_ms:
    return "pcl_ms";
  case Method::gp3:
    return "gp3";
  case Method::poisson:
    return "poisson";
  case Method::afsr:
    return "afsr";
  }
  return "unknown";
}

std::string methodLabel(Method method) {
  switch (method) {
  case Method::pcl_ms:
    return "pcl_ms";
  case Method::gp3:
    return "PCL GP3";
  case Method::poisson:
    return "PCL Poisson";
  case Method::afsr:
    return "CGAL AFSR";
  }
  return "unknown";
}

bool parseMethod(const std::string &text, Method &method) {
  std::string key = text;
  std::transform(key.begin(), key.end(), key.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (key == "ours")
    key = "pcl_ms";
  for (Method candidate : allMethods())
    if (methodKey(candidate) == key) {
      method = candidate;
      return true;
    }
  return false;
}

double PeerRun::seconds() const {
  double total = 0;
  for (const StageTime &stage : stages)
    total += stage.seconds;
  return total;
}

PeerRun runPeer(Method method, const pcl::PointCloud<pcl::PointXYZ> &points,
                const PeerSettings &settings, const StageCallback &on_stage) {
  const double start = residentMb();
  PeerRun run = runMethod(method, points, settings, on_stage);
  fillInputVertices(points, run);
  run.peak_mb = peakResidentMb();
  run.start_mb = start;
  return run;
}

PeerRun runPeerInChild(Method method, const pcl::PointCloud<pcl::PointXYZ> &points,
                       const PeerSettings &settings, const StageCallback &on_stage) {
  const ChildOutcome outcome = runInChild([&] {
    PeerRun run = runMethod(method, points, settings, on_stage);
    run.peak_mb = peakResidentMb(); // before the copy that goes into the pipe
    return serialize(run);
  });
  PeerRun run;
  run.method = method;
  if (outcome.ok) {
    try {
      deserialize(outcome.payload, run);
    } catch (const std::exception &exception) {
      run = PeerRun();
      run.method = method;
      run.error = exception.what();
    }
  } else {
    run.error = oneLine(outcome.error);
  }
  if (!(run.peak_mb > 0))
    run.peak_mb = outcome.peak_mb;
  run.start_mb = outcome.start_mb;
  fillInputVertices(points, run);
  return run;
}

} // namespace pcl_ms_tools
