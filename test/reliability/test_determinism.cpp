/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Determinism on a real scan (the bundled stereo scan, 307,200 points with holes and
// noise): identical labels, leaves, segments and mesh across repeated runs, thread
// counts and point orders; and byte-identical output files from the tool.
// Arguments: the tool's path, then the bundled scan.

#include <pcl_selective_seg/selective_segmentation.h>

#include <gtest/gtest.h>
#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using pcl::selective_seg::SelectiveSegmentation;
using pcl::selective_seg::SelectiveSegmentationParameters;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

namespace {

std::string tool; // NOLINT: set once in main()
std::string scan; // NOLINT: set once in main()

/** What a run produced, in terms of input point indices only. */
struct Snapshot {
  std::vector<std::uint32_t> labels;
  std::vector<std::tuple<float, float, float, float, std::uint32_t, std::uint32_t>> leaves;
  std::vector<std::pair<std::size_t, std::size_t>> segments; ///< points, leaves
  std::set<std::array<pcl::index_t, 4>> triangles;           ///< sorted corners, label
};

/** Segments \a cloud; indices in the snapshot are mapped through \a original (the
 * original index of each point of \a cloud). */
Snapshot
segment(const Cloud::ConstPtr& cloud,
        const std::vector<pcl::index_t>& original,
        int threads)
{
  SelectiveSegmentationParameters p;
  p.num_threads = threads;
  SelectiveSegmentation<pcl::PointXYZ> seg;
  seg.setParameters(p);
  seg.setSensorPose(Eigen::Affine3f::Identity());
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> clusters;
  Snapshot s;
  if (!seg.extract(clusters))
    return s;
  const auto& r = seg.getResult();
  s.labels.resize(r.labels.size());
  for (std::size_t i = 0; i < r.labels.size(); ++i)
    s.labels[original[i]] = r.labels[i];
  for (const auto& l : r.leaves)
    s.leaves.emplace_back(l.centre.x(), l.centre.y(), l.centre.z(), l.size, l.depth, l.label);
  for (const auto& seg_info : r.segments)
    s.segments.emplace_back(seg_info.num_points, seg_info.num_leaves);
  for (std::size_t t = 0; t < r.mesh.triangles.size(); ++t) {
    std::array<pcl::index_t, 4> key{};
    for (int k = 0; k < 3; ++k)
      key[k] = original[r.mesh.triangles[t][k]];
    std::sort(key.begin(), key.begin() + 3);
    key[3] = static_cast<pcl::index_t>(r.mesh.labels[t]);
    s.triangles.insert(key);
  }
  return s;
}

Cloud::Ptr
loadScan()
{
  auto cloud = pcl::make_shared<Cloud>();
  if (scan.empty() || pcl::io::loadPCDFile(scan, *cloud) != 0)
    cloud->clear();
  return cloud;
}

} // namespace

TEST(Determinism, RunsThreadCountsAndPointOrdersAgree)
{
  const auto cloud = loadScan();
  if (cloud->empty())
    GTEST_SKIP() << "bundled scan missing";
  std::vector<pcl::index_t> identity(cloud->size());
  std::iota(identity.begin(), identity.end(), 0);
  const Snapshot reference = segment(cloud, identity, 1);
  ASSERT_EQ(reference.labels.size(), cloud->size());
  ASSERT_GT(reference.segments.size(), 100u);
  // The shared vertices' representative is the nearest point, ties by coordinates:
  // a shuffled organized scan with duplicates of one point still agrees.
  for (const int threads : {1, 2, 3, 0}) {
    const Snapshot again = segment(cloud, identity, threads);
    EXPECT_EQ(again.labels, reference.labels) << threads << " threads";
    EXPECT_EQ(again.leaves, reference.leaves) << threads << " threads";
    EXPECT_EQ(again.segments, reference.segments) << threads << " threads";
    EXPECT_EQ(again.triangles, reference.triangles) << threads << " threads";
  }
  for (const unsigned seed : {1u, 2u}) {
    std::vector<pcl::index_t> order = identity;
    std::shuffle(order.begin(), order.end(), std::mt19937(seed));
    auto shuffled = pcl::make_shared<Cloud>();
    shuffled->reserve(cloud->size());
    for (const auto i : order)
      shuffled->push_back((*cloud)[i]);
    const Snapshot s = segment(shuffled, order, seed == 1 ? 2 : 1);
    EXPECT_EQ(s.labels, reference.labels) << "shuffle " << seed;
    EXPECT_EQ(s.segments, reference.segments) << "shuffle " << seed;
    EXPECT_EQ(s.triangles, reference.triangles) << "shuffle " << seed;
    // Leaves: same voxels and labels (the octree frame is the points' extent).
    EXPECT_EQ(s.leaves, reference.leaves) << "shuffle " << seed;
  }
}

// The tool writes byte-identical files whatever the number of OpenMP threads.
TEST(Determinism, ToolOutputsAreByteIdentical)
{
  if (tool.empty() || !fs::exists(tool) || scan.empty() || !fs::exists(scan))
    GTEST_SKIP() << "tool or scan missing";
  const fs::path dir = fs::temp_directory_path() /
                       ("selseg_determinism_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const auto read = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), {});
  };
  std::map<std::string, std::string> first;
  for (const int threads : {1, 2, 1}) {
    const std::string command =
        "OMP_NUM_THREADS=" + std::to_string(threads) + " '" + tool + "' '" + scan +
        "' -ignore_viewpoint -o '" + (dir / "labels.pcd").string() + "' -mesh_ply '" +
        (dir / "mesh.ply").string() + "' -mesh_vtk '" + (dir / "mesh.vtk").string() +
        "' -leaves '" + (dir / "leaves.pcd").string() + "' > /dev/null 2>&1";
    const int status = std::system(command.c_str());
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << command;
    for (const char* name : {"labels.pcd", "mesh.ply", "mesh.vtk", "leaves.pcd"}) {
      const std::string content = read(dir / name);
      ASSERT_FALSE(content.empty()) << name;
      if (first.count(name)) {
        EXPECT_TRUE(content == first[name]) << name << " differs with " << threads
                                            << " threads";
      }
      else {
        first[name] = content;
      }
    }
  }
  fs::remove_all(dir);
}

int
main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  pcl::console::setVerbosityLevel(pcl::console::L_ERROR);
  if (argc > 2) {
    tool = argv[1];
    scan = argv[2];
  }
  return RUN_ALL_TESTS();
}
