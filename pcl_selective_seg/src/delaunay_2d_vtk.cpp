/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <vtkCellArray.h>
#include <vtkCellArrayIterator.h>
#include <vtkCommand.h>
#include <vtkDelaunay2D.h>
#include <vtkExecutive.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <cctype>
#include <string>

#include "delaunay_2d_backends.h"

namespace pcl {
namespace selective_seg {
namespace detail {

namespace {

/** vtkDelaunay2D discards a point closer to an earlier one than Tolerance times the
 * diagonal of the points' bounding box. Distinct quantized points are at least 1 apart
 * and the diagonal is at most 2 * sqrt(2) * 2^26 < 1.9e8, so with 1e-9 the merge
 * distance stays below 0.19 and no distinct point is ever discarded. */
constexpr double kVtkTolerance = 1e-9;

/** Records the errors VTK reports instead of letting it print them. */
class ErrorObserver : public vtkCommand {
public:
  static ErrorObserver* New() { return new ErrorObserver; }

  void Execute(vtkObject*, unsigned long, void* call_data) override
  {
    if (!message.empty())
      return;
    // "ERROR: In <file>, line <n>\n<class> (<address>): ERROR: <text>\n\n": the text.
    message = call_data ? static_cast<const char*>(call_data) : "unknown error";
    const auto text = message.rfind("ERROR: ");
    if (text != std::string::npos)
      message.erase(0, text + 7);
    while (!message.empty() && std::isspace(static_cast<unsigned char>(message.back())))
      message.pop_back();
  }

  std::string message;
};

/** Whether the triangles can be part of a planar triangulation of the points: each
 * directed edge used at most once, and at most 2 n - 5 triangles. */
bool
checkResult(const std::vector<QuantizedPoint>& points,
            const std::vector<Triangle>& triangles,
            std::string* error)
{
  std::vector<std::pair<index_t, index_t>> edges;
  edges.reserve(3 * triangles.size());
  for (const auto& t : triangles)
    for (int i = 0; i < 3; ++i)
      edges.emplace_back(t[i], t[(i + 1) % 3]);
  std::sort(edges.begin(), edges.end());
  const bool overlap = std::adjacent_find(edges.begin(), edges.end()) != edges.end();
  if (!overlap && triangles.size() + 5 <= 2 * points.size())
    return true;
  setError(error,
           "delaunay2d (vtk): vtkDelaunay2D returned " +
               std::to_string(triangles.size()) + " triangles for " +
               std::to_string(points.size()) + " points" +
               (overlap ? ", some overlapping (an edge used twice)" : ""));
  return false;
}

vtkSmartPointer<vtkPolyData>
toPolyData(const std::vector<QuantizedPoint>& points)
{
  auto vtk_points = vtkSmartPointer<vtkPoints>::New();
  vtk_points->SetDataTypeToDouble();
  vtk_points->SetNumberOfPoints(static_cast<vtkIdType>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i)
    vtk_points->SetPoint(static_cast<vtkIdType>(i), points[i][0], points[i][1], 0.0);
  auto poly_data = vtkSmartPointer<vtkPolyData>::New();
  poly_data->SetPoints(vtk_points);
  return poly_data;
}

/** Appends the triangle with ids (a, b, c) counter-clockwise by the exact orientation;
 * degenerate (collinear) triangles are dropped. */
void
appendOriented(const std::vector<QuantizedPoint>& points,
               index_t a,
               index_t b,
               index_t c,
               std::vector<Triangle>& triangles)
{
  const std::int64_t o = orientation(points[a], points[b], points[c]);
  if (o > 0)
    triangles.push_back({a, b, c});
  else if (o < 0)
    triangles.push_back({a, c, b});
}

} // namespace

bool
delaunayVtk(const std::vector<QuantizedPoint>& points,
            std::vector<Triangle>& triangles,
            std::string* error)
{
  triangles.clear();
  auto delaunay = vtkSmartPointer<vtkDelaunay2D>::New();
  delaunay->SetInputData(toPolyData(points));
  delaunay->SetTolerance(kVtkTolerance);
  // An error of the filter (such as "Edge is non-manifold") or of its pipeline is a
  // failure; observed, it is not printed by VTK.
  auto errors = vtkSmartPointer<ErrorObserver>::New();
  delaunay->AddObserver(vtkCommand::ErrorEvent, errors);
  delaunay->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, errors);
  delaunay->Update();
  if (!errors->message.empty()) {
    setError(error, "delaunay2d (vtk): vtkDelaunay2D failed: " + errors->message);
    return false;
  }
  vtkCellArray* polys = delaunay->GetOutput()->GetPolys();
  if (!polys) {
    setError(error, "delaunay2d (vtk): vtkDelaunay2D produced no polygons");
    return false;
  }
  // vtkDelaunay2D keeps the input points, so its point ids are the input ids.
  const auto num_points = static_cast<vtkIdType>(points.size());
  auto cell = vtk::TakeSmartPointer(polys->NewIterator());
  for (cell->GoToFirstCell(); !cell->IsDoneWithTraversal(); cell->GoToNextCell()) {
    vtkIdType size = 0;
    const vtkIdType* ids = nullptr;
    cell->GetCurrentCell(size, ids);
    if (size != 3 || ids[0] >= num_points || ids[1] >= num_points ||
        ids[2] >= num_points)
      continue;
    appendOriented(points,
                   static_cast<index_t>(ids[0]),
                   static_cast<index_t>(ids[1]),
                   static_cast<index_t>(ids[2]),
                   triangles);
  }
  if (!checkResult(points, triangles, error)) {
    triangles.clear();
    return false;
  }
  return true;
}

} // namespace detail
} // namespace selective_seg
} // namespace pcl
