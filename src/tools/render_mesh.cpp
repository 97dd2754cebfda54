// SPDX-License-Identifier: GPL-3.0-or-later
#include "render_mesh.h"

#include "offscreen_display.h"

#include <vtkActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkErrorCode.h>
#include <vtkImageAppend.h>
#include <vtkImageData.h>
#include <vtkMapper.h>
#include <vtkNew.h>
#include <vtkOpenGLRenderWindow.h>
#include <vtkPNGReader.h>
#include <vtkPNGWriter.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <Eigen/Geometry>
#include <png.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

namespace pcl_ms_tools {
namespace {

// Oblique and slightly from below (y is up in the Stanford scans), so the
// bunny is seen from its front left and the holes in its base show.
const Eigen::Vector3d kDefaultDirection(-0.45, -0.6, 1.0);
const Eigen::Vector3d kDefaultUp(0, 1, 0);
constexpr double kViewAngleDegrees = 30; // across the smaller side of the picture
constexpr double kFramedFraction = 0.85; // of the view angle taken by the points
constexpr int kMaxPictureSide = 8192;
constexpr std::uint64_t kMaxPixelsToRead = std::uint64_t(1) << 28;
constexpr int kMultiSamples = 4; // smooth edges; 8 costs twice the time in llvmpipe
constexpr double kEdgeDepthPull = -300;

const std::array<double, 3> kSurfaceColour{0.80, 0.80, 0.78};
const std::array<double, 3> kBoundaryColour{0.0, 0.2, 1.0};
const std::array<double, 3> kNonManifoldColour{0.9, 0.0, 0.0};

// The message of a VTK error event, without the source location line and the
// "vtkClass (0x...): " prefix.
std::string vtkMessage(const char *text) {
  std::string message = text ? text : "";
  while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
    message.pop_back();
  const std::size_t line_start = message.find_last_of('\n');
  if (line_start != std::string::npos)
    message.erase(0, line_start + 1);
  const std::size_t prefix_end = message.find("): ");
  if (prefix_end != std::string::npos)
    message.erase(0, prefix_end + 3);
  return message.empty() ? "unknown VTK error" : message;
}

// Collects the errors of the VTK objects it watches instead of letting VTK
// print them. Watching ExitEvent matters: VTK 9.1 calls abort() when it
// cannot create a GLX context unless someone observes that event. Declare it
// before the objects it watches, so it outlives them.
class VtkProblems {
public:
  VtkProblems() {
    callback_->SetClientData(this);
    callback_->SetCallback(&VtkProblems::record);
  }

  void watch(vtkObject *object) {
    object->AddObserver(vtkCommand::ErrorEvent, callback_);
    object->AddObserver(vtkCommand::ExitEvent, callback_);
  }

  bool any() const { return !first_.empty(); }
  const std::string &first() const { return first_; }

private:
  static void record(vtkObject *, unsigned long event, void *self, void *message) {
    std::string &first = static_cast<VtkProblems *>(self)->first_;
    if (!first.empty())
      return;
    first = event == vtkCommand::ExitEvent ? "VTK gave up on the OpenGL context"
                                           : vtkMessage(static_cast<const char *>(message));
  }

  vtkNew<vtkCallbackCommand> callback_;
  std::string first_;
};

// An off-screen OpenGL render window on `display` whose failures are
// reported to `problems`, or nullptr when VTK's OpenGL factory is missing.
vtkSmartPointer<vtkOpenGLRenderWindow> makeWindow(void *display, int width, int height,
                                                  VtkProblems &problems) {
  vtkSmartPointer<vtkOpenGLRenderWindow> window =
      vtkOpenGLRenderWindow::SafeDownCast(vtkSmartPointer<vtkRenderWindow>::New());
  if (!window)
    return nullptr;
  problems.watch(window);
  window->SetDisplayId(display);
  window->SetOffScreenRendering(1);
  window->SetSize(width, height);
  return window;
}

const char *const kNoOpenGLWindow =
    "VTK has no OpenGL render window (vtkRenderingOpenGL2 is not initialised)";

// The DisplayCheck of OffscreenSession: an OpenGL 3.2 context and a shader.
bool openGlWorks(void *display, std::string &error) {
  VtkProblems problems;
  vtkSmartPointer<vtkOpenGLRenderWindow> window = makeWindow(display, 16, 16, problems);
  if (!window) {
    error = kNoOpenGLWindow;
    return false;
  }
  window->Initialize();
  if (problems.any()) {
    error = problems.first();
    return false;
  }
  // Safe now that a context was created: the test window it makes has no observers.
  if (!window->SupportsOpenGL()) {
    error = window->GetOpenGLSupportMessage();
    return false;
  }
  return true;
}

bool isFinite(const Eigen::Vector3d &v) { return v.allFinite(); }

// The faces, and the edges drawn in colour: boundary edges (one triangle) and
// non-manifold edges (more than two).
struct MeshGeometry {
  vtkNew<vtkPolyData> faces;
  vtkNew<vtkPolyData> boundary_edges;
  vtkNew<vtkPolyData> non_manifold_edges;
};

void buildGeometry(const std::vector<Eigen::Vector3d> &vertices,
                   const std::vector<pcl_ms::Triangle> &triangles, MeshGeometry &geometry) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(vertices.size()));
  for (std::size_t i = 0; i < vertices.size(); ++i)
    points->SetPoint(static_cast<vtkIdType>(i), vertices[i].data());

  using Edge = std::pair<pcl_ms::VertexIndex, pcl_ms::VertexIndex>;
  std::vector<Edge> edges; // one entry per (triangle, distinct edge)
  edges.reserve(3 * triangles.size());
  vtkNew<vtkCellArray> polygons;
  for (const pcl_ms::Triangle &triangle : triangles) {
    const bool valid = std::all_of(triangle.begin(), triangle.end(), [&](pcl_ms::VertexIndex v) {
      return v < vertices.size() && isFinite(vertices[v]);
    });
    if (!valid)
      continue;
    const vtkIdType corners[3] = {triangle[0], triangle[1], triangle[2]};
    polygons->InsertNextCell(3, corners);
    const std::size_t first_edge = edges.size();
    for (int k = 0; k < 3; ++k) {
      const pcl_ms::VertexIndex a = triangle[k];
      const pcl_ms::VertexIndex b = triangle[(k + 1) % 3];
      const Edge edge = std::minmax(a, b);
      // A degenerate triangle (a, a, b) uses its edge (a, b) once, not twice.
      if (a != b && std::find(edges.begin() + static_cast<std::ptrdiff_t>(first_edge), edges.end(),
                              edge) == edges.end())
        edges.push_back(edge);
    }
  }
  std::sort(edges.begin(), edges.end());

  vtkNew<vtkCellArray> boundary_lines;
  vtkNew<vtkCellArray> non_manifold_lines;
  for (std::size_t start = 0, end; start < edges.size(); start = end) {
    end = start + 1;
    while (end < edges.size() && edges[end] == edges[start])
      ++end;
    const std::size_t triangle_count = end - start;
    const vtkIdType line[2] = {edges[start].first, edges[start].second};
    if (triangle_count == 1)
      boundary_lines->InsertNextCell(2, line);
    else if (triangle_count > 2)
      non_manifold_lines->InsertNextCell(2, line);
  }

  geometry.faces->SetPoints(points);
  geometry.faces->SetPolys(polygons);
  geometry.boundary_edges->SetPoints(points);
  geometry.boundary_edges->SetLines(boundary_lines);
  geometry.non_manifold_edges->SetPoints(points);
  geometry.non_manifold_edges->SetLines(non_manifold_lines);
}

vtkSmartPointer<vtkActor> makeActor(vtkPolyData *data, const std::array<double, 3> &colour) {
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(data);
  mapper->ScalarVisibilityOff();
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(colour[0], colour[1], colour[2]);
  return actor;
}

// Flat shaded, so every triangle shows, and with enough ambient light that
// faces seen edge-on stay grey rather than black.
vtkSmartPointer<vtkActor> makeSurfaceActor(vtkPolyData *faces) {
  vtkSmartPointer<vtkActor> actor = makeActor(faces, kSurfaceColour);
  vtkProperty *property = actor->GetProperty();
  property->SetInterpolationToFlat();
  property->SetAmbient(0.3);
  property->SetDiffuse(0.7);
  return actor;
}

// Coloured edge lines, unlit so they keep their colour, and wide enough to
// read over the shaded faces.
vtkSmartPointer<vtkActor> makeEdgeActor(vtkPolyData *edges, const std::array<double, 3> &colour,
                                        const RenderOptions &options) {
  vtkSmartPointer<vtkActor> actor = makeActor(edges, colour);
  // An edge lies in its faces, and the half of a wide line over a steep face
  // would be hidden by that face. A constant pull towards the camera (VTK
  // units of 1.6e-5 of the depth range) keeps both halves; the slope-scaled
  // polygon offset does not help with Mesa here. It is small enough that
  // edges behind the surface stay hidden.
  actor->GetMapper()->SetRelativeCoincidentTopologyLineOffsetParameters(0, kEdgeDepthPull);
  vtkProperty *property = actor->GetProperty();
  property->LightingOff();
  property->SetLineWidth(
      static_cast<float>(std::max(2.0, std::min(options.width, options.height) / 400.0)));
  return actor;
}

void addCaption(vtkRenderer *renderer, const RenderOptions &options) {
  if (options.caption.empty())
    return;
  vtkNew<vtkTextActor> caption;
  caption->SetInput(options.caption.c_str());
  vtkTextProperty *text = caption->GetTextProperty();
  text->SetFontSize(std::max(12, options.height / 28));
  text->SetColor(0, 0, 0);
  text->SetJustificationToCentered();
  text->SetVerticalJustificationToTop();
  caption->SetDisplayPosition(options.width / 2, options.height - options.height / 80 - 2);
  renderer->AddActor2D(caption);
}

void placeCamera(vtkRenderer *renderer, const RenderView &view, const RenderOptions &options) {
  const Eigen::Vector3d direction = view.direction.normalized();
  Eigen::Vector3d up = view.up - view.up.dot(direction) * direction;
  up = up.norm() > 1e-9 * view.up.norm() && up.norm() > 0 ? up.normalized()
                                                          : direction.unitOrthogonal();
  const Eigen::Vector3d position = view.look_at + view.distance * direction;
  vtkCamera *camera = renderer->GetActiveCamera();
  camera->SetFocalPoint(view.look_at.data());
  camera->SetPosition(position.data());
  camera->SetViewUp(up.data());
  camera->SetViewAngle(kViewAngleDegrees);
  camera->SetUseHorizontalViewAngle(options.width < options.height);
  renderer->ResetCameraClippingRange();
}

std::string checkRenderRequest(const RenderView &view, const RenderOptions &options) {
  if (options.width < 1 || options.height < 1 || options.width > kMaxPictureSide ||
      options.height > kMaxPictureSide)
    return "picture size " + std::to_string(options.width) + "x" + std::to_string(options.height) +
           " is not between 1 and " + std::to_string(kMaxPictureSide);
  if (!isFinite(view.look_at) || !isFinite(view.direction) || !isFinite(view.up) ||
      !std::isfinite(view.distance))
    return "the view has a non-finite value";
  if (view.direction.norm() == 0)
    return "the view direction is zero";
  if (view.distance <= 0)
    return "the view distance is not positive";
  return "";
}

// Why the PNG file cannot be decoded, or "" when it can. vtkPNGReader
// crashes on truncated or corrupt files (libpng's error jump is not caught),
// so each file is decoded once with libpng's checked API first.
std::string pngProblem(const std::string &path) {
  png_image image;
  std::memset(&image, 0, sizeof image);
  image.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&image, path.c_str()))
    return image.message;
  if (static_cast<std::uint64_t>(image.width) * image.height > kMaxPixelsToRead) {
    png_image_free(&image);
    return "too large";
  }
  image.format = PNG_FORMAT_RGBA;
  std::vector<png_byte> pixels(PNG_IMAGE_SIZE(image));
  const bool decoded = png_image_finish_read(&image, nullptr, pixels.data(), 0, nullptr) != 0;
  const std::string message = image.message;
  png_image_free(&image);
  return decoded ? "" : message.empty() ? "cannot be decoded" : message;
}

} // namespace

RenderView viewFramingPoints(const std::vector<Eigen::Vector3d> &points) {
  RenderView view;
  view.direction = kDefaultDirection.normalized();
  view.up = kDefaultUp;

  // Camera axes: right, up and towards the camera.
  const Eigen::Vector3d right = view.up.cross(view.direction).normalized();
  const Eigen::Vector3d camera_up = view.direction.cross(right);
  Eigen::AlignedBox3d box;
  Eigen::AlignedBox2d across; // the points seen along the view direction
  for (const Eigen::Vector3d &point : points)
    if (isFinite(point)) {
      box.extend(point);
      across.extend(Eigen::Vector2d(point.dot(right), point.dot(camera_up)));
    }
  if (box.isEmpty())
    return view;
  // Centred on the points as the camera sees them, so the picture is balanced.
  const Eigen::Vector3d centre = box.center();
  view.look_at = centre + (across.center().x() - centre.dot(right)) * right +
                 (across.center().y() - centre.dot(camera_up)) * camera_up;

  // The nearest camera that sees every point inside the view cone.
  const double half_angle_tangent =
      std::tan(0.5 * kFramedFraction * kViewAngleDegrees * M_PI / 180.0);
  double distance = 0;
  for (const Eigen::Vector3d &point : points)
    if (isFinite(point)) {
      const Eigen::Vector3d offset = point - view.look_at;
      const double sideways =
          std::max(std::abs(offset.dot(right)), std::abs(offset.dot(camera_up)));
      distance = std::max(distance, offset.dot(view.direction) + sideways / half_angle_tangent);
    }
  if (distance > 0)
    view.distance = distance;
  return view;
}

bool renderMeshPng(const std::vector<Eigen::Vector3d> &vertices,
                   const std::vector<pcl_ms::Triangle> &triangles, const RenderView &view,
                   const RenderOptions &options, const std::string &png_path, std::string &error) {
  error = checkRenderRequest(view, options);
  if (!error.empty())
    return false;
  MeshGeometry geometry;
  buildGeometry(vertices, triangles, geometry);

  // Declared before the VTK objects, so both outlive them.
  OffscreenSession session;
  VtkProblems problems;
  void *display = session.display(&openGlWorks, error);
  if (!display) {
    error = "cannot render off-screen: " + error;
    return false;
  }

  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(1, 1, 1);
  renderer->TwoSidedLightingOn(); // flipped faces are lit like the others
  // Enables the edge offset of makeEdgeActor(). VTK 9.1 leaves offsets off
  // by default, and the switch is global.
  vtkMapper::SetResolveCoincidentTopologyToPolygonOffset();
  renderer->AddActor(makeSurfaceActor(geometry.faces));
  renderer->AddActor(makeEdgeActor(geometry.boundary_edges, kBoundaryColour, options));
  renderer->AddActor(makeEdgeActor(geometry.non_manifold_edges, kNonManifoldColour, options));
  addCaption(renderer, options);
  placeCamera(renderer, view, options);

  vtkSmartPointer<vtkOpenGLRenderWindow> window =
      makeWindow(display, options.width, options.height, problems);
  if (!window) {
    error = kNoOpenGLWindow;
    return false;
  }
  window->SetMultiSamples(kMultiSamples);
  window->AddRenderer(renderer);
  window->Initialize();
  if (!problems.any() && session.xError().empty())
    window->Render();
  const std::string x_error = session.xError();
  if (problems.any() || !x_error.empty()) {
    error = "cannot render off-screen: " + (problems.any() ? problems.first() : x_error);
    return false;
  }

  vtkNew<vtkWindowToImageFilter> capture;
  problems.watch(capture);
  capture->SetInput(window);
  capture->SetInputBufferTypeToRGB();
  capture->ReadFrontBufferOff();
  capture->Update();
  const int *size = capture->GetOutput()->GetDimensions();
  if (problems.any() || size[0] != options.width || size[1] != options.height) {
    error = "cannot read the rendered picture back" +
            (problems.any() ? ": " + problems.first() : std::string());
    return false;
  }

  vtkNew<vtkPNGWriter> writer;
  problems.watch(writer);
  writer->SetFileName(png_path.c_str());
  writer->SetInputConnection(capture->GetOutputPort());
  writer->Write();
  if (problems.any() || writer->GetErrorCode() != vtkErrorCode::NoError) {
    error = "cannot write " + png_path + ": " +
            (problems.any() ? problems.first()
                            : vtkErrorCode::GetStringFromErrorCode(writer->GetErrorCode()));
    return false;
  }
  return true;
}

bool composeSideBySide(const std::vector<std::string> &png_paths, const std::string &output_path,
                       std::string &error) {
  error.clear();
  if (png_paths.empty()) {
    error = "no pictures to put side by side";
    return false;
  }
  VtkProblems problems;
  vtkNew<vtkImageAppend> append;
  append->SetAppendAxis(0);
  std::vector<vtkSmartPointer<vtkPNGReader>> readers;
  int first_height = 0;
  int first_channels = 0;
  int first_scalar_type = 0;
  for (const std::string &path : png_paths) {
    const std::string problem = pngProblem(path);
    if (!problem.empty()) {
      error = "cannot read " + path + ": " + problem;
      return false;
    }
    auto reader = vtkSmartPointer<vtkPNGReader>::New();
    problems.watch(reader);
    reader->SetFileName(path.c_str());
    reader->Update();
    if (problems.any() || reader->GetErrorCode() != vtkErrorCode::NoError) {
      error = "cannot read " + path + ": " +
              (problems.any() ? problems.first()
                              : vtkErrorCode::GetStringFromErrorCode(reader->GetErrorCode()));
      return false;
    }
    vtkImageData *image = reader->GetOutput();
    const int *size = image->GetDimensions();
    const int channels = image->GetNumberOfScalarComponents();
    const int scalar_type = image->GetScalarType();
    if (readers.empty()) {
      first_height = size[1];
      first_channels = channels;
      first_scalar_type = scalar_type;
    } else if (size[1] != first_height) {
      error = "cannot put " + path + " (height " + std::to_string(size[1]) + ") next to " +
              png_paths.front() + " (height " + std::to_string(first_height) +
              "): the heights differ";
      return false;
    } else if (channels != first_channels || scalar_type != first_scalar_type) {
      error = "cannot put " + path + " next to " + png_paths.front() +
              ": their pixel formats (channels or bit depth) differ";
      return false;
    }
    append->AddInputConnection(reader->GetOutputPort());
    readers.push_back(reader);
  }
  problems.watch(append);

  vtkNew<vtkPNGWriter> writer;
  problems.watch(writer);
  writer->SetFileName(output_path.c_str());
  writer->SetInputConnection(append->GetOutputPort());
  writer->Write();
  if (problems.any() || writer->GetErrorCode() != vtkErrorCode::NoError) {
    error = "cannot write " + output_path + ": " +
            (problems.any() ? problems.first()
                            : vtkErrorCode::GetStringFromErrorCode(writer->GetErrorCode()));
    return false;
  }
  return true;
}

} // namespace pcl_ms_tools
