#include "postprocess/render.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataSet.h>
#include <vtkDataSetSurfaceFilter.h>
#include <vtkLookupTable.h>
#include <vtkMapper.h>
#include <vtkMath.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkWindowToImageFilter.h>
#include <vtkXMLPUnstructuredGridReader.h>
#include <vtkXMLReader.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <GL/glx.h>
#include <GL/glxext.h>
#include <X11/Xlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <utility>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/number_format.h"
#include "common/paths.h"
#include "mesher/vtk_messages.h"

namespace hexbite {

namespace {

// Set by x_error_caught while it is the X error handler: Xlib's own handler ends the process.
bool x_error_seen = false;
int x_error_caught(Display*, XErrorEvent*) {
  x_error_seen = true;
  return 0;
}

// Why no OpenGL context that VTK can draw with (3.2 or later) can be made on `config`, or empty. The GLX
// checks below passed on displays where VTK then aborted ("Cannot create GLX context. Aborting.", exit 134)
// or crashed: an OpenGL driver that does not load (as under `ulimit -v`), indirect GLX (LIBGL_ALWAYS_INDIRECT
// =1; X servers refuse it with an X error, whose default handler ends the process), an OpenGL older than
// VTK needs. So a context is made as VTK 9.1 makes it, made current on a tiny unmapped window, and freed,
// with X errors caught meanwhile.
std::string context_problem(Display* x, GLXFBConfig config) {
  XErrorHandler previous = XSetErrorHandler(x_error_caught);
  x_error_seen = false;
  const auto failed = [x] {  // an X error since the last check
    XSync(x, False);
    return std::exchange(x_error_seen, false);
  };
  XVisualInfo* visual = glXGetVisualFromFBConfig(x, config);
  const Window root = RootWindow(x, DefaultScreen(x));
  XSetWindowAttributes window_attributes{};  // with a border pixel: the visual need not be the root's
  window_attributes.colormap = visual == nullptr ? None : XCreateColormap(x, root, visual->visual, AllocNone);
  const Window window = visual == nullptr
                            ? None
                            : XCreateWindow(x, root, 0, 0, 1, 1, 0, visual->depth, InputOutput,
                                            visual->visual, CWColormap | CWBorderPixel, &window_attributes);
  GLXContext context = nullptr;
  const auto keep_if_no_error = [&] {  // a context whose creation the server refused is no context
    if (failed() && context != nullptr) {
      glXDestroyContext(x, context);
      context = nullptr;
    }
  };
  std::string problem;
  if (window == None || failed()) {
    problem = "no window for OpenGL could be made";
  } else {
    // As VTK 9.1: a 3.2 context through GLX_ARB_create_context, else one of any version.
    const auto create_with_attributes = reinterpret_cast<PFNGLXCREATECONTEXTATTRIBSARBPROC>(
        glXGetProcAddressARB(reinterpret_cast<const GLubyte*>("glXCreateContextAttribsARB")));
    const int version_3_2[] = {GLX_CONTEXT_MAJOR_VERSION_ARB, 3, GLX_CONTEXT_MINOR_VERSION_ARB, 2, None};
    if (create_with_attributes != nullptr) {
      context = create_with_attributes(x, config, nullptr, True, version_3_2);
      keep_if_no_error();
    }
    if (context == nullptr) {
      context = glXCreateNewContext(x, config, GLX_RGBA_TYPE, nullptr, True);
      keep_if_no_error();
    }
    if (context == nullptr) {
      problem =
          "no OpenGL context could be made (the X server refused it, as with LIBGL_ALWAYS_INDIRECT=1, "
          "or the OpenGL driver did not load: not installed, or too little memory under ulimit -v?)";
    } else if (!glXMakeContextCurrent(x, window, window, context) || failed()) {
      problem = "its OpenGL context cannot be used";
    } else {
      const auto get_string = reinterpret_cast<const GLubyte* (*)(GLenum)>(
          glXGetProcAddressARB(reinterpret_cast<const GLubyte*>("glGetString")));
      const char* version =
          get_string == nullptr ? nullptr : reinterpret_cast<const char*>(get_string(GL_VERSION));
      int major = 0, minor = 0;
      if (version == nullptr || std::sscanf(version, "%d.%d", &major, &minor) != 2 ||
          std::make_pair(major, minor) < std::make_pair(3, 2))
        problem = std::string("its OpenGL is version ") + (version == nullptr ? "unknown" : version) +
                  ", and VTK needs 3.2 or later";
      glXMakeContextCurrent(x, None, None, nullptr);
    }
  }
  if (context != nullptr) glXDestroyContext(x, context);
  if (window != None) XDestroyWindow(x, window);
  if (window_attributes.colormap != None) XFreeColormap(x, window_attributes.colormap);
  if (visual != nullptr) XFree(visual);
  failed();  // the errors of these requests are still this handler's
  XSetErrorHandler(previous);
  return problem;
}

// The process's connection to the X server, or nullptr when it does not answer. It stays open for the
// process's life: an X server without other clients (xvfb-run's) resets when the last one leaves, and VTK's
// own connection, made right after the check's, was refused now and then during that reset. VTK draws
// through it as well: with a connection of its own the OpenGL driver was set up twice, for the check's
// context and for VTK's, and under a `ulimit -v` that the check had passed VTK then crashed for want of room.
Display* x_connection() {
  static Display* const connection = XOpenDisplay(nullptr);
  return connection;
}

std::string check_display() {
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr || *display == '\0') return "DISPLAY is not set";
  // A DISPLAY left over from a closed ssh session or an ended Xvfb: VTK would abort on it.
  Display* const probe = x_connection();
  if (probe == nullptr) return std::string("the X display '") + display + "' does not answer";
  // A display that answers but cannot give VTK an OpenGL context (an X server without the GLX extension,
  // as many ssh -X and VNC servers are, or an 8-bit screen without a colour visual with a depth buffer):
  // VTK aborted on it ("Could not find a decent config", exit 134), and `report` left its temporary folder.
  int error_base = 0, event_base = 0;
  if (!glXQueryExtension(probe, &error_base, &event_base))
    return std::string("the X display '") + display + "' has no OpenGL: its X server lacks the GLX extension";
  const int attributes[] = {GLX_DRAWABLE_TYPE,
                            GLX_WINDOW_BIT,
                            GLX_RENDER_TYPE,
                            GLX_RGBA_BIT,
                            GLX_RED_SIZE,
                            1,
                            GLX_GREEN_SIZE,
                            1,
                            GLX_BLUE_SIZE,
                            1,
                            GLX_DEPTH_SIZE,
                            1,
                            None};
  int configs = 0;
  GLXFBConfig* found = glXChooseFBConfig(probe, DefaultScreen(probe), attributes, &configs);
  const std::string problem = configs == 0 ? std::string() : context_problem(probe, found[0]);
  if (found != nullptr) XFree(found);
  if (configs == 0)
    return std::string("the X display '") + display +
           "' has no OpenGL: no visual with colour and depth (a screen of 8 bits per pixel?)";
  if (!problem.empty())
    return std::string("the X display '") + display + "' has no usable OpenGL: " + problem;
  return {};
}

}  // namespace

// Checked once: a report asks before each picture, and making an OpenGL context takes a while.
std::string display_problem() {
  static const std::string problem = check_display();
  return problem;
}

namespace {

vtkSmartPointer<vtkPolyData> to_polydata(const TriSurface& surface) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(surface.vertices.size()));
  for (std::size_t i = 0; i < surface.vertices.size(); ++i)
    points->SetPoint(static_cast<vtkIdType>(i), surface.vertices[i].data());
  vtkNew<vtkCellArray> cells;
  for (const auto& t : surface.triangles) {
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    cells->InsertNextCell(3, ids);
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetPolys(cells);
  return poly;
}

// Camera directions in the anatomical frame (+x subject's left, +y posterior, +z superior).
void place_camera(vtkCamera* camera, const std::string& view) {
  camera->SetFocalPoint(0, 0, 0);
  if (view == "side") {  // from the subject's right
    camera->SetPosition(-1, 0, 0);
    camera->SetViewUp(0, 0, 1);
  } else if (view == "front") {
    camera->SetPosition(0, -1, 0);
    camera->SetViewUp(0, 0, 1);
  } else if (view == "back") {
    camera->SetPosition(0, 1, 0);
    camera->SetViewUp(0, 0, 1);
  } else if (view == "top") {
    camera->SetPosition(0, 0, 1);
    camera->SetViewUp(0, -1, 0);
  } else if (view == "iso") {
    camera->SetPosition(-1, -1.2, 0.8);
    camera->SetViewUp(0, 0, 1);
  } else {
    throw InputError("unknown view '" + view + "': use iso, side, front, back or top");
  }
}

}  // namespace

namespace {

// Where `data`'s points fall in the picture, in view coordinates ([-1, 1] across and up): {x0, x1, y0, y1}.
std::array<double, 4> view_extent(vtkCamera* camera, vtkDataSet* data, double aspect) {
  vtkMatrix4x4* m = camera->GetCompositeProjectionTransformMatrix(aspect, -1, 1);
  std::array<double, 4> e = {1e300, -1e300, 1e300, -1e300};
  for (vtkIdType i = 0; i < data->GetNumberOfPoints(); ++i) {
    double p[4] = {0, 0, 0, 1}, q[4];
    data->GetPoint(i, p);
    m->MultiplyPoint(p, q);
    e[0] = std::min(e[0], q[0] / q[3]);
    e[1] = std::max(e[1], q[0] / q[3]);
    e[2] = std::min(e[2], q[1] / q[3]);
    e[3] = std::max(e[3], q[1] / q[3]);
  }
  return e;
}

// Zooms and shifts the camera until the object's points fill the picture with a margin, left of the
// colour legend when there is one, across as well as up. VTK's ResetCamera fits the bounding sphere into the
// vertical view angle only, and the fixed zoom used before cut off tall objects, and wide ones in portrait
// pictures.
void frame_object(vtkRenderer* renderer, vtkActor* actor, double aspect, bool legend) {
  vtkCamera* camera = renderer->GetActiveCamera();
  actor->GetMapper()->Update();
  vtkDataSet* data = actor->GetMapper()->GetInput();
  if (data == nullptr || data->GetNumberOfPoints() == 0) return;
  // The legend (vtkScalarBarActor's default place) starts at 0.82 of the width: x = 0.64.
  const double x0 = -0.94, x1 = legend ? 0.56 : 0.94, y0 = -0.9, y1 = 0.92;
  // The view angle spans the picture's shorter side, so that it stays well below VTK's limit of 179
  // degrees whatever the picture's shape.
  camera->SetUseHorizontalViewAngle(aspect < 1);
  for (int round = 0; round < 3; ++round) {
    renderer->ResetCameraClippingRange();
    std::array<double, 4> e = view_extent(camera, data, aspect);
    const double scale =
        std::min((x1 - x0) / std::max(e[1] - e[0], 1e-12), (y1 - y0) / std::max(e[3] - e[2], 1e-12));
    // The object's extent in the picture is proportional to 1 / tan(angle / 2), so that is what is scaled.
    // vtkCamera::Zoom divides the angle itself, far from that at wide angles: a tall narrow picture needed
    // them to take in the object's width, overshot and never settled, and cut the object off at both sides
    // or left it out of the picture.
    const double half_angle = vtkMath::RadiansFromDegrees(camera->GetViewAngle()) / 2;
    camera->SetViewAngle(vtkMath::DegreesFromRadians(2 * std::atan(std::tan(half_angle) / scale)));
    e = view_extent(camera, data, aspect);
    double centre[2];
    camera->GetWindowCenter(centre);
    camera->SetWindowCenter(centre[0] + (e[0] + e[1]) / 2 - (x0 + x1) / 2,
                            centre[1] + (e[2] + e[3]) / 2 - (y0 + y1) / 2);
  }
  renderer->ResetCameraClippingRange();
}

// Draws one actor (and optional 2-D actors) with the chosen view and writes the PNG.
void render_actor_png(vtkActor* actor, vtkActor2D* legend, const std::string& png_path,
                      const RenderOptions& options) {
  vtkNew<vtkCamera> camera;
  place_camera(camera, options.view);  // validates the view before anything is opened
  const std::string no_display = display_problem();
  if (!no_display.empty())
    throw RunError("cannot render '" + png_path + "': no X display (" + no_display +
                   "); run the command under `xvfb-run -a`");
  actor->GetProperty()->SetSpecular(0.2);
  if (options.edges) {
    actor->GetProperty()->EdgeVisibilityOn();
    actor->GetProperty()->SetEdgeColor(0.45, 0.42, 0.38);
  }

  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  if (legend != nullptr) renderer->AddActor2D(legend);
  renderer->SetBackground(1, 1, 1);
  renderer->SetActiveCamera(camera);
  renderer->ResetCamera();
  frame_object(renderer, actor, double(options.width) / options.height, legend != nullptr);
  if (!options.title.empty()) {
    vtkNew<vtkTextActor> text;
    text->SetInput(options.title.c_str());
    text->GetTextProperty()->SetFontSize(22);
    text->GetTextProperty()->SetColor(0.1, 0.1, 0.1);
    text->SetDisplayPosition(16, 16);
    renderer->AddActor2D(text);
  }

  vtkNew<vtkRenderWindow> window;
  window->SetDisplayId(x_connection());
  window->SetOffScreenRendering(1);
  window->AddRenderer(renderer);
  window->SetSize(options.width, options.height);
  window->Render();

  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->ReadFrontBufferOff();
  grab->Update();
  // Encoded in memory and written like every other output: libpng's own complaints about a failed file
  // write ("libpng error: Write Error") went to the terminal beside our message.
  std::string png;
  {
    VtkMessageCapture capture;  // what VTK says goes into the error, not to the terminal as its coloured log
    vtkNew<vtkPNGWriter> writer;
    writer->WriteToMemoryOn();
    writer->SetInputConnection(grab->GetOutputPort());
    writer->Write();
    vtkUnsignedCharArray* bytes = writer->GetResult();
    if (writer->GetErrorCode() != 0 || !capture.errors().empty() || bytes == nullptr)
      throw RunError("cannot encode the picture '" + png_path + "'" +
                     (capture.errors().empty() ? std::string() : ": " + capture.errors()));
    png.assign(reinterpret_cast<const char*>(bytes->GetPointer(0)),
               static_cast<std::size_t>(bytes->GetNumberOfValues()));
  }
  write_file_atomically(png_path, png);
}

// Refuses a .pvtu whose piece file is missing, naming that file: VTK said only "File for piece 0 cannot be
// read." of the .pvtu. The pieces lie beside it unless their Source is absolute, as VTK reads them.
void require_pvtu_pieces(const std::string& pvtu_path) {
  std::ifstream in(pvtu_path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  const std::string xml = text.str();
  static const std::regex kPiece(R"re(<Piece\b[^>]*\bSource="([^"]*)")re");
  std::size_t index = 0;
  for (auto it = std::sregex_iterator(xml.begin(), xml.end(), kPiece); it != std::sregex_iterator();
       ++it, ++index) {
    const std::filesystem::path source((*it)[1].str());
    const std::string piece =
        (source.is_absolute() ? source : std::filesystem::path(pvtu_path).parent_path() / source).string();
    std::error_code ec;
    if (!std::filesystem::exists(piece, ec))
      throw InputError("'" + piece + "' (piece " + std::to_string(index) + " of '" + pvtu_path +
                       "') does not exist: a run under mpirun writes its pieces beside the .pvtu; copy them "
                       "with it, or run the scenario again");
  }
}

}  // namespace

void render_surface_png(const TriSurface& surface, const std::string& png_path,
                        const RenderOptions& options) {
  vtkNew<vtkPolyDataNormals> normals;  // smooth shading without changing the geometry
  normals->SetInputData(to_polydata(surface));
  normals->SplittingOff();
  normals->ConsistencyOff();
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(normals->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(0.93, 0.89, 0.80);  // bone
  render_actor_png(actor, nullptr, png_path, options);
}

RenderedMesh render_mesh_png(const std::string& vtu_path, const std::string& field,
                             const std::string& png_path, const RenderOptions& options) {
  require_regular_file(vtu_path, "mesh file");
  // A .pvtu (the pieces of a run under mpirun) is read whole: its pieces appended into one grid. The nodes
  // that pieces share appear once per piece, so the faces between pieces count as outer faces too; they
  // lie inside the bone and are hidden in the picture.
  const bool pieces = lower_extension(vtu_path) == ".pvtu";
  if (pieces) require_pvtu_pieces(vtu_path);
  vtkSmartPointer<vtkXMLReader> reader;
  if (pieces)
    reader = vtkSmartPointer<vtkXMLPUnstructuredGridReader>::New();
  else
    reader = vtkSmartPointer<vtkXMLUnstructuredGridReader>::New();
  vtkUnstructuredGrid* grid = nullptr;
  {
    VtkMessageCapture capture;
    if (reader->CanReadFile(vtu_path.c_str()) != 0) {
      reader->SetFileName(vtu_path.c_str());
      update_xml_reader(reader, vtu_path);
      grid = vtkUnstructuredGrid::SafeDownCast(reader->GetOutputDataObject(0));
    }
    if (!capture.errors().empty() || grid == nullptr || grid->GetNumberOfCells() == 0)
      throw InputError("cannot read '" + vtu_path + "' as a VTK unstructured grid (" +
                       (pieces ? ".pvtu and its pieces" : ".vtu") + ") with cells" + capture.reason());
  }

  RenderedMesh drawn;
  drawn.cells = static_cast<long>(grid->GetNumberOfCells());
  vtkNew<vtkDataSetSurfaceFilter> outer;  // only the boundary faces are visible
  outer->SetInputData(grid);
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(outer->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  vtkNew<vtkScalarBarActor> bar;
  vtkNew<vtkLookupTable> colours;
  if (field.empty()) {
    mapper->ScalarVisibilityOff();
    actor->GetProperty()->SetColor(0.93, 0.89, 0.80);
    render_actor_png(actor, nullptr, png_path, options);
    return drawn;
  }
  // A point array (a solution field such as von_mises), else a cell array (the per-hex quality arrays that
  // hexbite mesh, refine and reorder write, such as scaled_jacobian): each hex's face in its colour.
  vtkDataArray* array = grid->GetPointData()->GetArray(field.c_str());
  const bool per_cell = array == nullptr && grid->GetCellData()->GetArray(field.c_str()) != nullptr;
  if (per_cell) array = grid->GetCellData()->GetArray(field.c_str());
  // The names of the file's arrays, or of its arrays of one component only.
  const auto array_names = [&](bool scalars_only) {
    std::string names;
    for (auto [data, per_hex] : {std::pair{static_cast<vtkFieldData*>(grid->GetPointData()), ""},
                                 std::pair{static_cast<vtkFieldData*>(grid->GetCellData()), " (per hex)"}})
      for (int i = 0; i < data->GetNumberOfArrays(); ++i)
        if (!scalars_only ||
            (data->GetArray(i) != nullptr && data->GetArray(i)->GetNumberOfComponents() == 1))
          names += std::string(names.empty() ? "" : ", ") + data->GetArrayName(i) + per_hex;
    return names.empty() ? std::string("none") : names;
  };
  if (array == nullptr)
    throw InputError("'" + vtu_path + "' has no point or cell array '" + field +
                     "'; available: " + array_names(false));
  // One component, the magnitude of the displacement vector (as documented), or the component that
  // --component picks. Before, every array of several components was coloured by its norm: the stress
  // tensor's 6 components by sqrt(xx^2 + ... + xz^2), which is no stress measure, and the principal
  // stresses without their sign, compression in the colour of tension.
  const int components = array->GetNumberOfComponents();
  const std::string what = "'" + field + "' in '" + vtu_path + "'";
  std::string component_names;
  for (int c = 0; c < components; ++c)
    component_names += (c == 0 ? "" : ", ") + std::to_string(c) +
                       (array->GetComponentName(c) ? std::string(" ") + array->GetComponentName(c) : "");
  if (components == 1 && options.component >= 0)
    throw InputError(what + " has one component: drop --component");
  const bool magnitude = components == 3 && !per_cell && field == "displacement" && options.component < 0;
  if (components > 1 && !magnitude && options.component < 0)
    throw InputError(
        what + " has " + std::to_string(components) + " components (" + component_names +
        "): pick one with --component N, or colour by an array of one component: " + array_names(true));
  if (options.component >= components)
    throw InputError("--component " + std::to_string(options.component) + " is not a component of " + what +
                     ", which has " + std::to_string(components) + " (" + component_names + ")");
  const int component = components == 1 ? 0 : magnitude ? -1 : options.component;  // -1: magnitude
  std::string legend = field;
  if (component >= 0 && components > 1)
    legend += array->GetComponentName(component) ? std::string(" ") + array->GetComponentName(component)
                                                 : " component " + std::to_string(component);
  double range[2];
  array->GetRange(range, component);
  drawn.field_max = range[1];
  // Stress peaks at the edges of fixed patches would wash out the rest of the picture: let the caller
  // cap the scale (values above it show in the top colour).
  if (options.colour_max > 0) {
    // A top below every value left VTK with an inverted table ("Bad table range") and a legend of 0 to 1.
    if (!(options.colour_max > range[0]))
      throw InputError(
          "the colour scale's top, " + format_significant(options.colour_max) +
          ", is not above the smallest value of '" + field + "' in '" + vtu_path +
          "' (the values range from " + format_rounded(range[0]) + " to " + format_rounded(range[1]) +
          "): every face would show in one colour; give a --max above " + format_rounded(range[0]));
    range[1] = options.colour_max;
  }
  colours->SetHueRange(0.667, 0.0);  // blue (low) to red (high)
  colours->SetTableRange(range);
  colours->Build();
  mapper->SetLookupTable(colours);
  if (per_cell)
    mapper->SetScalarModeToUseCellFieldData();
  else
    mapper->SetScalarModeToUsePointFieldData();
  mapper->SelectColorArray(field.c_str());
  if (component < 0) {
    colours->SetVectorModeToMagnitude();
  } else {
    colours->SetVectorModeToComponent();
    colours->SetVectorComponent(component);
  }
  mapper->SetScalarRange(range);
  mapper->ScalarVisibilityOn();
  bar->SetLookupTable(colours);
  bar->SetTitle(legend.c_str());
  bar->SetNumberOfLabels(5);
  bar->SetMaximumWidthInPixels(110);
  // VTK draws the title right on top of the bar, where it touched the top label ("von_mises" over "10.0").
  bar->SetVerticalTitleSeparation(12);
  bar->GetTitleTextProperty()->SetColor(0.1, 0.1, 0.1);
  bar->GetLabelTextProperty()->SetColor(0.1, 0.1, 0.1);
  render_actor_png(actor, bar, png_path, options);
  return drawn;
}

}  // namespace hexbite
