/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#pragma once

#include <pcl_selective_seg/parameters.h>
#include <pcl_selective_seg/segmentation_result.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace selseg_apps {

/** \brief The same file, as far as the paths tell (symbolic links and "." resolved):
 * an output naming the input, or two outputs naming one file, are refused with it. */
bool samePath(const std::string& a, const std::string& b);

/** \brief Whether an output file can be written, checked before the work that makes
 * it: not a folder, device, FIFO or socket (OutputTransaction::check()), and its folder
 * exists and takes a file (a probe file beside it, removed at once).
 * \param[out] error the failure, naming the file and what to do */
bool outputWritable(const std::string& path, std::string& error);

/** \brief \a s as a JSON string, in quotes: quotes, backslashes and control characters
 * escaped, each ill-formed UTF-8 sequence (a file name's bytes need not be UTF-8)
 * replaced by U+FFFD, so that the file is valid JSON. */
std::string jsonString(const std::string& s);

/** \brief Output files written under temporary names and renamed into place only when
 * all of them were written: a failed run leaves no partial or stale output behind.
 *
 * A run ended by SIGTERM, SIGINT or SIGHUP leaves none either: the first stage()
 * installs a handler for each of them whose action is the default one (one that is
 * ignored stays ignored) that removes the staged temporaries of every transaction not
 * yet committed or destroyed, then re-raises the signal with the default action (the
 * exit status stays 128 + the signal's number). The handler reads the paths from a
 * fixed array of C strings, filled before the files are opened: it allocates nothing
 * and takes no lock. A path of 4 KiB or more, or beyond the array's 128 entries, is
 * not covered. */
class OutputTransaction {
public:
  OutputTransaction() = default;
  OutputTransaction(const OutputTransaction&) = delete;
  OutputTransaction& operator=(const OutputTransaction&) = delete;
  /** \brief Removes the temporary files of an uncommitted transaction. */
  ~OutputTransaction();

  /** \brief The temporary path to write \a final_path's content to. A symbolic link
   * is followed: the file is staged beside the link's target and replaces the target,
   * so that the link stays a link. */
  std::string stage(const std::string& final_path);

  /** \brief Whether commit() would refuse a final path staged so far: an existing
   * folder or other file that is not a regular one (a device, a FIFO, a socket), which
   * renaming would replace. Lets a tool refuse before the work of making the file.
   * \param[out] error the failure, naming the file */
  bool check(std::string& error) const;

  /** \brief Rename every staged file to its final path. Refused, before anything is
   * replaced, when check() fails.
   * \param[out] error the failure, naming the file */
  bool commit(std::string& error);

private:
  struct Staged {
    std::string temporary;
    std::string target; ///< the final path, symbolic links followed
    std::string given;  ///< the final path as given, for messages
    int signal_slot;    ///< the signal handler's entry of the temporary, or -1
  };
  /** Take the temporaries out of the signal handler's reach. */
  void releaseSignalSlots();
  std::vector<Staged> files_;
  bool committed_ = false;
};

// Each writer returns false when the file cannot be written completely.

/** \brief The labeled cloud (x y z label; the input's size, order, layout and
 * viewpoint) as a binary_compressed PCD that PCL reads, from the input and a label per
 * point. Compressed in chunks on \a threads threads (the bytes do not depend on them)
 * and written as they are made: no labeled copy of the cloud is held. */
bool writeLabeledCloud(const std::string& path,
                       const pcl::PointCloud<pcl::PointXYZ>& cloud,
                       const std::vector<std::uint32_t>& labels,
                       int threads = 1);

/** \brief The segmented mesh as binary PLY: the vertices the triangles use, and per
 * face its vertex indices, an RGB colour (segment hue; edge triangles white), its label
 * and its class (0 interior, 1 valid edge, 2 invalid edge). The bytes are made in
 * blocks on \a threads threads (the file does not depend on them). */
bool writeMeshPly(const std::string& path,
                  const pcl::PointCloud<pcl::PointXYZ>& cloud,
                  const pcl::selective_seg::SegmentedMesh& mesh,
                  int threads = 1);

/** \brief The same mesh as legacy binary VTK polydata, with the colours, labels and
 * classes as cell data (made on \a threads threads, as writeMeshPly()). */
bool writeMeshVtk(const std::string& path,
                  const pcl::PointCloud<pcl::PointXYZ>& cloud,
                  const pcl::selective_seg::SegmentedMesh& mesh,
                  int threads = 1);

/** \brief A point of the leaves file (writeLeaves()). */
struct EIGEN_ALIGN16 LeafPoint {
  PCL_ADD_POINT4D;
  float size;
  std::uint32_t depth;
  std::uint32_t label;
  float normal_x, normal_y, normal_z;
  float sigma_theta, sigma_phi;
  std::uint32_t num_points;
  PCL_MAKE_ALIGNED_OPERATOR_NEW
};

/** \brief The leaves file's point for a leaf (its area is left out). */
LeafPoint leafPoint(const pcl::selective_seg::OctreeLeaf& leaf);

/** \brief The octree leaves as a PCD, one point per leaf: x y z (centre, cloud frame)
 * size depth label normal_x normal_y normal_z sigma_theta sigma_phi num_points. The
 * bytes of pcl::io::savePCDFileBinary() for those points, made on \a threads threads
 * and written a block at a time (PCL maps the whole file, and a mapped page counts in
 * the resident memory). False for no leaf, as PCL's writer. */
bool writeLeaves(const std::string& path,
                 const std::vector<pcl::selective_seg::OctreeLeaf>& leaves,
                 int threads = 1);

/** \brief What the JSON summary reports besides the result. */
struct RunInfo {
  std::string input;
  std::size_t num_points = 0;
  std::string backend;
  pcl::selective_seg::SelectiveSegmentationParameters parameters;
  /** With the panoramic projection: whether the mesh closed around the sensor
   * (SphericalTriangulation::seam_closed), written as counts.seam_closed. */
  bool seam_closed = false;
};

/** \brief A JSON summary: input, parameters, counts, timings and every segment's size,
 * normal, area and leaf count (formatted on \a threads threads; the file does not
 * depend on them). */
bool writeSummaryJson(const std::string& path,
                      const RunInfo& info,
                      const pcl::selective_seg::SegmentationResult& result,
                      int threads = 1);

} // namespace selseg_apps

POINT_CLOUD_REGISTER_POINT_STRUCT(
    selseg_apps::LeafPoint,
    (float, x, x)(float, y, y)(float, z, z)(float, size, size)(
        std::uint32_t, depth, depth)(std::uint32_t, label, label)(
        float, normal_x, normal_x)(float, normal_y, normal_y)(
        float, normal_z, normal_z)(float, sigma_theta, sigma_theta)(
        float, sigma_phi, sigma_phi)(std::uint32_t, num_points, num_points))
