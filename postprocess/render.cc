#include "postprocess/render.h"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <cstdlib>

#include "common/atomic_file.h"
#include "common/error.h"

namespace hexbite {

bool can_render() {
  const char* display = std::getenv("DISPLAY");
  return display != nullptr && *display != '\0';
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

void render_surface_png(const TriSurface& surface, const std::string& png_path,
                        const RenderOptions& options) {
  vtkNew<vtkCamera> camera;
  place_camera(camera, options.view);  // validates the view before anything is opened
  if (!can_render())
    throw RunError("cannot render '" + png_path +
                   "': no X display (DISPLAY is not set); run the command under `xvfb-run -a`");

  vtkNew<vtkPolyDataNormals> normals;  // smooth shading without changing the geometry
  normals->SetInputData(to_polydata(surface));
  normals->SplittingOff();
  normals->ConsistencyOff();
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(normals->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(0.93, 0.89, 0.80);  // bone
  actor->GetProperty()->SetSpecular(0.2);
  if (options.edges) {
    actor->GetProperty()->EdgeVisibilityOn();
    actor->GetProperty()->SetEdgeColor(0.45, 0.42, 0.38);
  }

  vtkNew<vtkRenderer> renderer;
  renderer->AddActor(actor);
  renderer->SetBackground(1, 1, 1);
  renderer->SetActiveCamera(camera);
  renderer->ResetCamera();
  camera->Zoom(1.3);
  if (!options.title.empty()) {
    vtkNew<vtkTextActor> text;
    text->SetInput(options.title.c_str());
    text->GetTextProperty()->SetFontSize(22);
    text->GetTextProperty()->SetColor(0.1, 0.1, 0.1);
    text->SetDisplayPosition(16, 16);
    renderer->AddActor2D(text);
  }

  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->AddRenderer(renderer);
  window->SetSize(options.width, options.height);
  window->Render();

  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->ReadFrontBufferOff();
  grab->Update();
  write_atomically(png_path, [&](const std::string& tmp) {
    vtkNew<vtkPNGWriter> writer;
    writer->SetFileName(tmp.c_str());
    writer->SetInputConnection(grab->GetOutputPort());
    writer->Write();
    if (writer->GetErrorCode() != 0) throw RunError("cannot write '" + png_path + "'");
  });
}

}  // namespace hexbite
