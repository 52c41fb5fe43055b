/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl/octree/octree_container.h>

#include <algorithm>
#include <cstddef>

namespace pcl {
namespace selective_seg {

/** \brief Leaf container of OctreePointCloudNormalVariance: the point indices of one
 * finest voxel, plus where they start in the octree's depth-first ordering of all
 * points. With that ordering the points of every node, leaf or branch, form one
 * contiguous range, so the statistics of eq. 4-5 of any node are one pass over it.
 *
 * The octree's bulk insertion stores every leaf's indices in one array of the tree and
 * each container views its part of it (no allocation per leaf); PCL's point-by-point
 * insertion (addPointIndex()) stores them in the container. A copy always holds its
 * own indices. */
class OctreeNormalVarianceContainer : public pcl::octree::OctreeContainerBase {
public:
  OctreeNormalVarianceContainer() = default;

  OctreeNormalVarianceContainer(const OctreeNormalVarianceContainer& other)
      : OctreeContainerBase(other)
      , owned_(other.begin(), other.end())
      , first_(other.first_)
  {
  }

  OctreeNormalVarianceContainer& operator=(const OctreeNormalVarianceContainer& other)
  {
    if (this != &other) {
      owned_.assign(other.begin(), other.end());
      view_ = nullptr;
      view_size_ = 0;
      first_ = other.first_;
    }
    return *this;
  }

  OctreeNormalVarianceContainer* deepCopy() const
  {
    return new OctreeNormalVarianceContainer(*this);
  }

  bool operator==(const pcl::octree::OctreeContainerBase& other) const override
  {
    const auto* same = dynamic_cast<const OctreeNormalVarianceContainer*>(&other);
    return same && std::equal(begin(), end(), same->begin(), same->end());
  }

  pcl::uindex_t getSize() const override
  {
    return view_ ? view_size_ : static_cast<pcl::uindex_t>(owned_.size());
  }

  void reset() override
  {
    owned_.clear();
    view_ = nullptr;
    view_size_ = 0;
    first_ = 0;
  }

  void addPointIndex(pcl::index_t index) override
  {
    if (view_) {
      owned_.assign(begin(), end());
      view_ = nullptr;
      view_size_ = 0;
    }
    owned_.push_back(index);
  }

  /** \brief The last index (undefined when empty, as in PCL's containers). */
  pcl::index_t getPointIndex() const override { return *(end() - 1); }

  void getPointIndices(pcl::Indices& indices) const override
  {
    indices.insert(indices.end(), begin(), end());
  }

  /** \brief The indices, in insertion order. */
  const pcl::index_t* begin() const { return view_ ? view_ : owned_.data(); }
  const pcl::index_t* end() const { return begin() + getSize(); }

  /** \brief View \a count indices stored elsewhere; they must outlive the view (the
   * octree keeps them for as long as its tree). */
  void viewPointIndices(const pcl::index_t* first, pcl::uindex_t count)
  {
    pcl::Indices().swap(owned_);
    view_ = first;
    view_size_ = count;
  }

  /** \brief Position of this voxel's first point in the depth-first ordering. */
  std::size_t getFirstOrderedPoint() const { return first_; }

  void setFirstOrderedPoint(std::size_t first) { first_ = first; }

private:
  pcl::Indices owned_;
  const pcl::index_t* view_ = nullptr;
  pcl::uindex_t view_size_ = 0;
  std::size_t first_ = 0;
};

} // namespace selective_seg
} // namespace pcl
