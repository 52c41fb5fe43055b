/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#include <vtkCellArray.h>
#include <vtkCellArrayIterator.h>
#include <vtkDelaunay2D.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

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
  delaunay->Update();
  vtkCellArray* polys = delaunay->GetOutput()->GetPolys();
  if (!polys) {
    if (error)
      *error = "delaunay2d (vtk): vtkDelaunay2D produced no polygons";
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
  return true;
}

} // namespace detail
} // namespace selective_seg
} // namespace pcl
