/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// End-to-end tests of the command-line tool: outputs, exit codes, no partial output.
// Arguments: the tool's path, then the bundled scan.

#include <pcl_selective_seg/parameters.h>

#include <gtest/gtest.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/common/io.h>
#include <pcl/conversions.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "huge_page_advice.h"
#include "outputs.h"
#include "process_memory.h"
#include "reliability/reliability_util.h"
#include "roi_json.h"
#include "scan_io.h"
#include "segment_colors.h"

namespace fs = std::filesystem;

namespace {

std::string tool;  // NOLINT: set once in main()
std::string scan;  // NOLINT: set once in main()

/** Run the tool with arguments, after an optional environment assignment
 * ("NAME=value"); its exit code. */
int
run(const std::string& args, const std::string& env = "")
{
  const std::string command = (env.empty() ? "" : "env " + env + " ") + "'" + tool +
                              "' " + args + " > /dev/null 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/** The bytes of a file ("" when it cannot be read). */
std::string
fileBytes(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

/** A fresh folder under the temporary directory, removed with everything in it when it
 * goes out of scope (also when an assertion ends the test). */
class ScratchDir {
public:
  explicit ScratchDir(const std::string& name)
      : path_(fs::temp_directory_path() / (name + "_" + std::to_string(::getpid())))
  {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~ScratchDir()
  {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const fs::path& path() const { return path_; }
  /** The path of \a name in it. */
  std::string file(const std::string& name) const { return (path_ / name).string(); }

private:
  fs::path path_;
};

class Tool : public ::testing::Test {
protected:
  void
  SetUp() override
  {
    if (tool.empty() || !fs::exists(tool) || !fs::exists(scan))
      GTEST_SKIP() << "tool or scan missing";
    dir.emplace(std::string("selseg_tool_") +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  std::string out(const std::string& name) const { return dir->file(name); }
  std::size_t
  files() const
  {
    return static_cast<std::size_t>(
        std::distance(fs::directory_iterator(dir->path()), fs::directory_iterator()));
  }
  std::optional<ScratchDir> dir;
};

/** The element count a PLY header declares. */
std::size_t
plyCount(const std::string& path, const std::string& element)
{
  std::ifstream in(path, std::ios::binary);
  std::string line;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream words(line);
    std::string keyword, name;
    std::size_t count = 0;
    if (words >> keyword >> name >> count && keyword == "element" && name == element)
      return count;
  }
  return 0;
}

} // namespace

TEST_F(Tool, WritesEveryOutputInInputOrder)
{
  ASSERT_EQ(run("'" + scan + "' -ignore_viewpoint -o " + out("labels.pcd") +
                " -mesh_ply " + out("mesh.ply") + " -mesh_vtk " + out("mesh.vtk") +
                " -leaves " + out("leaves.pcd") + " -json " + out("summary.json")),
            0);
  pcl::PointCloud<pcl::PointXYZ> input;
  pcl::PointCloud<pcl::PointXYZL> labeled;
  ASSERT_EQ(pcl::io::loadPCDFile(scan, input), 0);
  ASSERT_EQ(pcl::io::loadPCDFile(out("labels.pcd"), labeled), 0);
  ASSERT_EQ(labeled.size(), input.size());
  EXPECT_EQ(labeled.width, input.width);
  EXPECT_EQ(labeled.height, input.height);
  std::size_t labeled_points = 0;
  for (std::size_t i = 0; i < input.size(); ++i) {
    const bool finite = std::isfinite(input[i].z);
    ASSERT_EQ(finite, std::isfinite(labeled[i].z)) << i;
    if (finite)
      ASSERT_EQ(labeled[i].getVector3fMap(), input[i].getVector3fMap()) << i;
    else
      ASSERT_EQ(labeled[i].label, 0u) << i;
    labeled_points += labeled[i].label > 0;
  }
  EXPECT_EQ(labeled_points, 209280u);

  // The JSON summary and the meshes agree on the counts.
  const std::string text = fileBytes(out("summary.json"));
  EXPECT_NE(text.find("\"labeled\": 209280"), std::string::npos);
  const auto at = text.find("\"triangles\": ");
  ASSERT_NE(at, std::string::npos);
  const std::size_t triangles = std::stoul(text.substr(at + 13));
  EXPECT_EQ(plyCount(out("mesh.ply"), "face"), triangles);
  EXPECT_GT(plyCount(out("mesh.ply"), "vertex"), 200000u);
  pcl::PolygonMesh mesh;
  ASSERT_EQ(pcl::io::loadPLYFile(out("mesh.ply"), mesh), 0);
  EXPECT_EQ(mesh.polygons.size(), triangles);
  std::ifstream vtk(out("mesh.vtk"));
  std::string first_line;
  std::getline(vtk, first_line);
  EXPECT_EQ(first_line, "# vtk DataFile Version 3.0");

  pcl::PCLPointCloud2 leaves;
  ASSERT_EQ(pcl::io::loadPCDFile(out("leaves.pcd"), leaves), 0);
  for (const char* field : {"x", "size", "depth", "label", "normal_x", "sigma_theta"})
    EXPECT_GE(pcl::getFieldIndex(leaves, field), 0) << field;
  EXPECT_GT(leaves.width * leaves.height, 1000u);
  EXPECT_EQ(files(), 5u); // no temporary left behind
}

TEST_F(Tool, UnreadableInputIsARuntimeErrorWithNoOutput)
{
  EXPECT_EQ(run(out("missing.pcd") + " -o " + out("labels.pcd")), 1);
  std::ofstream(out("broken.pcd")) << "not a point cloud\n";
  EXPECT_EQ(run(out("broken.pcd") + " -o " + out("labels.pcd")), 1);
  std::ofstream(out("broken.xyz")) << "1 2 3\n4 five 6\n";
  EXPECT_EQ(run(out("broken.xyz") + " -o " + out("labels.pcd")), 1);
  pcl::PointCloud<pcl::Intensity> no_xyz;
  no_xyz.resize(10);
  ASSERT_EQ(pcl::io::savePCDFileASCII(out("no_xyz.pcd"), no_xyz), 0);
  EXPECT_EQ(run(out("no_xyz.pcd") + " -o " + out("labels.pcd")), 1);
  EXPECT_FALSE(fs::exists(out("labels.pcd")));
  EXPECT_EQ(files(), 3u); // only the three broken inputs
}

TEST_F(Tool, NoUsablePointIsARuntimeError)
{
  // The file's VIEWPOINT puts every point behind the sensor.
  EXPECT_EQ(run("'" + scan + "' -o " + out("labels.pcd")), 1);
  EXPECT_EQ(files(), 0u);
}

TEST_F(Tool, PanoramicProjectionSegmentsPointsBehindTheSensor)
{
  // The same file with the panoramic projection: every point has an image.
  ASSERT_EQ(run("'" + scan + "' -projection panoramic -o " + out("labels.pcd") +
                " -json " + out("summary.json") + " -roi_json " + out("rois.json")),
            0);
  const std::string summary = fileBytes(out("summary.json"));
  for (const char* entry : {"\"projection\": \"panoramic\"",
                            "\"spread_frame\": \"mean_normal\"", // implied
                            "\"behind_sensor\": 0",
                            // a forward view's narrow band of azimuths: left open
                            "\"seam_closed\": false"})
    EXPECT_NE(summary.find(entry), std::string::npos) << entry;
  EXPECT_NE(fileBytes(out("rois.json")).find("\"projection\": \"panoramic\""),
            std::string::npos);
  std::vector<pcl::selective_seg::RegionOfInterest> regions;
  std::string error;
  ASSERT_TRUE(selseg_apps::readRegionsJson(out("rois.json"), regions, error)) << error;
  ASSERT_FALSE(regions.empty());
  for (const auto& r : regions)
    EXPECT_EQ(r.projection, pcl::selective_seg::ViewProjection::Panoramic);
  const std::string in = "'" + scan + "' -o " + out("other.pcd");
  EXPECT_EQ(run(in + " -projection panoramic -spread_frame sensor"), 2);
  EXPECT_EQ(run(in + " -projection sideways"), 2);
  EXPECT_EQ(run(in + " -projection panoramic -backend vtk"), 2);
  EXPECT_FALSE(fs::exists(out("other.pcd")));
}

// A degree option out of range is named with its value and unit: the library checks
// radians, and its message alone ("max_merge_angle [rad] = 3.49 is invalid") named
// neither the option nor the unit it was given in.
TEST_F(Tool, DegreeOptionsOutOfRangeNameTheOption)
{
  const std::string in = "'" + scan + "' -ignore_viewpoint -o " + out("labels.pcd");
  const std::string log = out("log.txt");
  for (const auto& [args, flag] :
       {std::make_pair(std::string(" -merge_deg 200"), std::string("-merge_deg 200")),
        std::make_pair(" -roi_json " + out("r.json") + " -roi_max_window_deg 200",
                       std::string("-roi_max_window_deg 200"))}) {
    const int status =
        std::system(("'" + tool + "' " + in + args + " > '" + log + "' 2>&1").c_str());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 2) << args;
    const std::string text = fileBytes(log);
    EXPECT_NE(text.find("Option " + flag + " [deg] is out of range"), std::string::npos)
        << text;
    EXPECT_NE(text.find("pi rad = 180 deg"), std::string::npos) << text;
  }
  EXPECT_FALSE(fs::exists(out("labels.pcd")));
}

TEST_F(Tool, BadOptionsAreUsageErrors)
{
  const std::string in = "'" + scan + "' -ignore_viewpoint -o " + out("labels.pcd");
  EXPECT_EQ(run(in + " -split_deg abc"), 2);
  EXPECT_EQ(run(in + " -merge_deg -5"), 2);
  EXPECT_EQ(run(in + " -min_voxel_m nan"), 2);
  EXPECT_EQ(run(in + " -backend cgal"), 2);
  EXPECT_EQ(run(in + " -normal_triangles some"), 2);
  EXPECT_EQ(run(in + " -no_such_option"), 2);
  EXPECT_EQ(run(in + " -sensor_origin 1,2"), 2);
  EXPECT_EQ(run(in + " -unit_scale 0"), 2);
  EXPECT_EQ(run(in + " -threads -1"), 2);
  EXPECT_EQ(run(in + " -threads ''"), 2); // empty: pcl::console would read 0 (all cores)
  // A repeated option: pcl::console's parsers used the first value silently.
  EXPECT_EQ(run(in + " -o " + out("second.pcd")), 2);
  EXPECT_EQ(run(in + " -split_deg 5 -split_deg 30"), 2);
  // A quaternion that cannot be normalized: 0 was taken as the identity, an overflowing
  // norm ended in a runtime error.
  EXPECT_EQ(run(in + " -sensor_orientation 0,0,0,0"), 2);
  EXPECT_EQ(run(in + " -sensor_orientation 1e300,1e300,0,0"), 2);
  EXPECT_EQ(run(""), 2);
  EXPECT_EQ(run("-h"), 0);
  EXPECT_EQ(files(), 0u);
}

TEST_F(Tool, SummaryRecordsEveryParameter)
{
  // A summary says how it was made: every segmentation option, given or default.
  ASSERT_EQ(run("'" + scan + "' -ignore_viewpoint -json " + out("summary.json") +
                " -spread_frame mean_normal -segment_weight area -normal_rings 2"
                " -merge_with segments"
                " -normal_triangles not_edge_on -edge_normal vertex_mean"
                " -voxel_factor 3 -max_depth 12 -angle_step_rad 2e-7"),
            0);
  const std::string text = fileBytes(out("summary.json"));
  for (const char* entry : {"\"split_deg\": 7.6",
                            "\"incidence_deg\": 85",
                            "\"spread_frame\": \"mean_normal\"",
                            "\"segment_weight\": \"area\"",
                            "\"merge_with\": \"segments\"",
                            "\"normal_rings\": 2",
                            "\"normal_triangles\": \"not_edge_on\"",
                            "\"edge_normal\": \"vertex_mean\"",
                            "\"voxel_factor\": 3",
                            "\"min_split_points\": 8",
                            "\"max_depth\": 12",
                            "\"angle_step_rad\": 2e-07",
                            "\"backend\": \"sweep\"",
                            "\"projection\": \"forward\""})
    EXPECT_NE(text.find(entry), std::string::npos) << entry;
}

TEST_F(Tool, ThreadCountKeepsTheOutput)
{
  const std::string in = "'" + scan + "' -ignore_viewpoint -o ";
  ASSERT_EQ(run(in + out("one.pcd") + " -threads 1 -roi_json " + out("one.json")), 0);
  ASSERT_EQ(run(in + out("two.pcd") + " -threads 2 -roi_json " + out("two.json")), 0);
  const std::string a = fileBytes(out("one.pcd"));
  const std::string b = fileBytes(out("two.pcd"));
  EXPECT_GT(a.size(), 1000u);
  EXPECT_EQ(a, b);
  // The regions of interest too (their passes run on the threads).
  EXPECT_GT(fileBytes(out("one.json")).size(), 1000u);
  EXPECT_EQ(fileBytes(out("one.json")), fileBytes(out("two.json")));
}

TEST_F(Tool, KeepingFreedMemoryKeepsTheOutput)
{
  // The tool keeps the memory it frees (keepFreedMemory()) unless the environment sets
  // glibc's malloc options, as MALLOC_ARENA_MAX does here: same bytes either way.
  const std::string in = "'" + scan + "' -ignore_viewpoint -o ";
  ASSERT_EQ(run(in + out("kept.pcd") + " -mesh_ply " + out("kept.ply")), 0);
  ASSERT_EQ(run(in + out("default.pcd") + " -mesh_ply " + out("default.ply"),
                "MALLOC_ARENA_MAX=8"),
            0);
  EXPECT_GT(fileBytes(out("kept.pcd")).size(), 1000u);
  EXPECT_EQ(fileBytes(out("kept.pcd")), fileBytes(out("default.pcd")));
  EXPECT_EQ(fileBytes(out("kept.ply")), fileBytes(out("default.ply")));
}

TEST_F(Tool, UnwritableOutputLeavesNothingBehind)
{
  EXPECT_EQ(run("'" + scan + "' -ignore_viewpoint -o " + out("labels.pcd") + " -json " +
                out("no/such/folder/summary.json")),
            1);
  EXPECT_EQ(files(), 0u); // the labeled cloud was not renamed into place either
}

TEST_F(Tool, ReadsTextInCentimetres)
{
  std::ofstream text(out("wall.xyz"));
  text << "# a wall 2 m in front of the sensor, in centimetres\n";
  for (int r = 0; r < 30; ++r)
    for (int c = 0; c < 30; ++c)
      text << 2 * c - 30 << " " << 2 * r - 30 << " 200\n";
  text.close();
  ASSERT_EQ(run(out("wall.xyz") + " -unit_scale 0.01 -o " + out("labels.pcd") +
                " -min_voxel_m 0.05"),
            0);
  pcl::PointCloud<pcl::PointXYZL> labeled;
  ASSERT_EQ(pcl::io::loadPCDFile(out("labels.pcd"), labeled), 0);
  ASSERT_EQ(labeled.size(), 900u);
  EXPECT_FLOAT_EQ(labeled[0].z, 2.0f);
  for (const auto& p : labeled)
    EXPECT_EQ(p.label, 1u);
}

/** Sets or clears an environment variable for the life of a scope. */
class ScopedEnv {
public:
  ScopedEnv(const char* name, const char* value)
      : name_(name)
  {
    if (const char* old = std::getenv(name)) {
      had_ = true;
      old_ = old;
    }
    if (value)
      setenv(name, value, 1);
    else
      unsetenv(name);
  }
  ~ScopedEnv()
  {
    if (had_)
      setenv(name_, old_.c_str(), 1);
    else
      unsetenv(name_);
  }
  ScopedEnv(const ScopedEnv&) = delete;
  ScopedEnv& operator=(const ScopedEnv&) = delete;

private:
  const char* name_;
  bool had_ = false;
  std::string old_;
};

TEST(KeepFreedMemory, YieldsToTheUsersMallocSettingsAndThenMapsNothing)
{
  // The user's settings win: nothing is changed while any is present.
  {
    ScopedEnv arenas("MALLOC_ARENA_MAX", "8");
    EXPECT_FALSE(selseg_apps::keepFreedMemory());
  }
  {
    ScopedEnv tunables("GLIBC_TUNABLES", "glibc.malloc.hugetlb=1");
    EXPECT_FALSE(selseg_apps::keepFreedMemory());
  }
#if defined(__GLIBC__)
  ScopedEnv tunables("GLIBC_TUNABLES", nullptr);
  for (const char* name : selseg_apps::kMallocOptionVariables)
    ASSERT_EQ(std::getenv(name), nullptr) << name << " is set: cannot test the default";
  if (!selseg_apps::keepFreedMemory())
    GTEST_SKIP() << "the allocator ignores mallopt() (a sanitizer's allocator)";
  // Without the setting glibc maps a 64 MB block on its own; now it comes from the
  // heap.
  const std::size_t mapped_before = mallinfo2().hblks;
  void* block = std::malloc(std::size_t{64} << 20);
  ASSERT_NE(block, nullptr);
  static_cast<volatile char*>(block)[0] = 1;
  EXPECT_EQ(mallinfo2().hblks, mapped_before);
  std::free(block);
  // Nor is a free top of 2 GB or more given back (with INT_MAX as the trim threshold it
  // was): 2.5 GB, one byte of it written.
  void* huge = std::malloc(std::size_t{5} << 29);
  if (huge) {
    static_cast<volatile char*>(huge)[0] = 1;
    const void* grown = sbrk(0);
    std::free(huge);
    EXPECT_EQ(sbrk(0), grown) << "the heap was trimmed";
  }
#else
  EXPECT_FALSE(selseg_apps::keepFreedMemory());
#endif
}

TEST_F(Tool, LoadScanGivesTheDeclaredPointsBeforeReadingThem)
{
  pcl::PointCloud<pcl::PointXYZ> cloud;
  std::string error;
  std::vector<std::size_t> declared;
  const auto note = [&](std::size_t n) {
    EXPECT_TRUE(cloud.empty()) << "called after the points were read";
    declared.push_back(n);
  };
  // A PCD: its WIDTH x HEIGHT (the bundled scan: 640 x 480, NaN points included).
  ASSERT_TRUE(selseg_apps::loadScan(scan, 1.0, cloud, error, note)) << error;
  EXPECT_EQ(declared, std::vector<std::size_t>{640 * 480});
  EXPECT_EQ(cloud.size(), 640u * 480u);
  // A PLY: its vertex count.
  pcl::PointCloud<pcl::PointXYZ> seven;
  for (int i = 0; i < 7; ++i)
    seven.push_back(pcl::PointXYZ(0.1f * i, 0.0f, 1.0f));
  ASSERT_EQ(pcl::io::savePLYFileBinary(out("seven.ply"), seven), 0);
  declared.clear();
  ASSERT_TRUE(selseg_apps::loadScan(out("seven.ply"), 1.0, cloud, error, note))
      << error;
  EXPECT_EQ(declared, std::vector<std::size_t>{7});
  EXPECT_EQ(cloud.size(), 7u);
  // Text declares nothing; a file refused before its header is checked, nothing either.
  std::ofstream(out("three.xyz")) << "0 0 1\n1 0 1\n0 1 1\n";
  declared.clear();
  ASSERT_TRUE(selseg_apps::loadScan(out("three.xyz"), 1.0, cloud, error, note))
      << error;
  EXPECT_EQ(cloud.size(), 3u);
  std::ofstream(out("broken.pcd")) << "VERSION 0.7\nFIELDS x y z\nDATA ascii\n";
  EXPECT_FALSE(selseg_apps::loadScan(out("broken.pcd"), 1.0, cloud, error, note));
  EXPECT_TRUE(declared.empty());
}

#if defined(__GLIBC__) && defined(SELSEG_TEST_HUGE_PAGE_ADVICE)
TEST(ReserveHeapInHugePages, LaterAllocationsComeFromAdvisedMemoryNotYetResident)
{
  EXPECT_FALSE(selseg_apps::reserveHeapInHugePages(0));
  SKIP_WITHOUT_HUGE_PAGE_ADVICE();
  ScopedEnv tunables("GLIBC_TUNABLES", nullptr);
  for (const char* name : selseg_apps::kMallocOptionVariables)
    ASSERT_EQ(std::getenv(name), nullptr) << name << " is set: cannot test the default";
  for (const int resource : {RLIMIT_AS, RLIMIT_DATA}) {
    rlimit limit{};
    ASSERT_EQ(getrlimit(resource, &limit), 0);
    if (limit.rlim_cur != RLIM_INFINITY)
      GTEST_SKIP() << "the address space or the data segment is limited (ulimit)";
  }
  if (!selseg_apps::keepFreedMemory())
    GTEST_SKIP() << "the allocator ignores mallopt() (a sanitizer's allocator)";
  // The tool's threshold; restored after the test.
  const std::size_t threshold = pcl::selective_seg::getHugePageAdviceThreshold();
  pcl::selective_seg::setHugePageAdviceThreshold(std::size_t{4} << 20);
  const std::size_t resident = selseg_test::procStatusBytes("VmRSS");
  const bool reserved = selseg_apps::reserveHeapInHugePages(std::size_t{256} << 20);
  const std::size_t resident_after = selseg_test::procStatusBytes("VmRSS");
  // A block taken from the heap afterwards lies in advised memory (without the
  // reservation, the heap grows by plain 4 KB pages).
  void* block = std::malloc(std::size_t{64} << 20);
  const bool block_advised =
      block && selseg_test::advised(selseg_test::firstHugePage(block) + (1 << 20));
  std::free(block);
  pcl::selective_seg::setHugePageAdviceThreshold(threshold);
  ASSERT_TRUE(reserved);
  EXPECT_TRUE(block_advised);
  // Nothing of the 256 MB was written.
  EXPECT_LT(resident_after, resident + (std::size_t{8} << 20));
  // Under a limit on the address space or the data segment (here 64 TB, then lifted
  // again), nothing.
  for (const int resource : {RLIMIT_AS, RLIMIT_DATA}) {
    rlimit unlimited{};
    ASSERT_EQ(getrlimit(resource, &unlimited), 0);
    rlimit limited = unlimited;
    limited.rlim_cur = rlim_t{1} << 46;
    ASSERT_EQ(setrlimit(resource, &limited), 0);
    const bool reserved_under_limit =
        selseg_apps::reserveHeapInHugePages(std::size_t{64} << 20);
    ASSERT_EQ(setrlimit(resource, &unlimited), 0);
    EXPECT_FALSE(reserved_under_limit)
        << (resource == RLIMIT_AS ? "RLIMIT_AS" : "RLIMIT_DATA");
  }
}
#endif

namespace {

using pcl::selective_seg::SegmentedMesh;
using pcl::selective_seg::TriangleClass;

/** Bytes of a 32-bit pattern, least significant first or last. */
std::string
bytes32(std::uint32_t bits, bool big_endian)
{
  std::string out(4, '\0');
  for (int i = 0; i < 4; ++i)
    out[big_endian ? 3 - i : i] = static_cast<char>((bits >> (8 * i)) & 0xffu);
  return out;
}

std::string
bytes8(std::uint8_t value)
{
  return std::string(1, static_cast<char>(value));
}

/** Points 0-4; the triangles use 3, 1, 4, 2 (in that order of first use), not 0. */
struct HandMadeMesh {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  SegmentedMesh mesh;
  // The coordinates' bit patterns (1 = 0x3f800000, 2 = 0x40000000, -1 = 0xbf800000,
  // 0.5 = 0x3f000000), by point.
  std::array<std::array<std::uint32_t, 3>, 5> bits{};
  HandMadeMesh()
  {
    const std::array<std::array<float, 3>, 5> xyz = {
        {{9, 9, 9}, {1, 0, 2}, {0.5f, 1, 2}, {-1, 0.5f, 2}, {0, 0, 1}}};
    const std::array<std::array<std::uint32_t, 3>, 5> patterns = {
        {{0x41100000, 0x41100000, 0x41100000},
         {0x3f800000, 0, 0x40000000},
         {0x3f000000, 0x3f800000, 0x40000000},
         {0xbf800000, 0x3f000000, 0x40000000},
         {0, 0, 0x3f800000}}};
    bits = patterns;
    for (const auto& p : xyz)
      cloud.push_back(pcl::PointXYZ(p[0], p[1], p[2]));
    mesh.triangles = {{3, 1, 4}, {1, 2, 4}};
    mesh.labels = {2, 1};
    mesh.classes = {TriangleClass::Interior, TriangleClass::ValidEdge};
  }
};

} // namespace

TEST(LeavesWriter, BytesOfPclsBinaryWriterForAnyThreadCount)
{
  // 60,000 leaves: several of the writer's blocks; values of every field distinct.
  std::vector<pcl::selective_seg::OctreeLeaf> leaves(60000);
  pcl::PointCloud<selseg_apps::LeafPoint> reference; // written by PCL
  for (std::size_t l = 0; l < leaves.size(); ++l) {
    auto& in = leaves[l];
    const auto f = static_cast<float>(l);
    in.centre = Eigen::Vector3f(f, -0.5f * f, 1.0f + 1e-3f * f);
    in.size = 0.01f * (1.0f + static_cast<float>(l % 7));
    in.depth = static_cast<std::uint32_t>(l % 11);
    in.label = static_cast<std::uint32_t>(l / 3);
    in.normal = Eigen::Vector3f(0.1f, -0.2f, f).normalized();
    in.sigma_theta = 1e-4f * f;
    in.sigma_phi = 2e-4f * f;
    in.area = 5.0; // not written
    in.num_points = static_cast<std::uint32_t>(l % 1000);
    reference.push_back(selseg_apps::leafPoint(in));
  }
  const ScratchDir dir("selseg_leaves_writer");
  ASSERT_EQ(pcl::io::savePCDFileBinary(dir.file("pcl.pcd"), reference), 0);
  const std::string expected = fileBytes(dir.file("pcl.pcd"));
  ASSERT_GT(expected.size(), 48u * leaves.size());
  for (const int threads : {1, 3}) {
    ASSERT_TRUE(selseg_apps::writeLeaves(dir.file("leaves.pcd"), leaves, threads));
    EXPECT_TRUE(fileBytes(dir.file("leaves.pcd")) == expected) << threads << " threads";
  }
  // No leaf: nothing to write, as PCL's writer refuses an empty cloud.
  EXPECT_FALSE(selseg_apps::writeLeaves(dir.file("none.pcd"), {}));
}

// The mesh files byte by byte: vertices numbered by first use, every number in the
// format's byte order, each face's colour (its segment's, or white on an edge), label
// and class.
TEST(MeshWriters, KnownBytesForAHandMadeMesh)
{
  const HandMadeMesh m;
  const ScratchDir dir("selseg_writers");
  const std::string ply = dir.file("mesh.ply"), vtk = dir.file("mesh.vtk");
  ASSERT_TRUE(selseg_apps::writeMeshPly(ply, m.cloud, m.mesh));
  ASSERT_TRUE(selseg_apps::writeMeshVtk(vtk, m.cloud, m.mesh));
  const std::array<int, 4> order = {3, 1, 4, 2}; // output vertex -> input point
  const std::array<std::array<std::uint32_t, 3>, 2> faces = {{{0, 1, 2}, {1, 3, 2}}};
  const selseg_apps::Rgb interior = selseg_apps::segmentColor(2);
  const std::array<selseg_apps::Rgb, 2> colors = {interior, {255, 255, 255}};
  ASSERT_NE(interior, (selseg_apps::Rgb{255, 255, 255}));

  std::string expected =
      "ply\nformat binary_little_endian 1.0\n"
      "comment pcl_selective_seg segmented mesh: edge triangles white\n"
      "element vertex 4\n"
      "property float x\nproperty float y\nproperty float z\n"
      "element face 2\n"
      "property list uchar int vertex_indices\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      "property uint label\nproperty uchar class\nend_header\n";
  for (const int p : order)
    for (const auto b : m.bits[p])
      expected += bytes32(b, false);
  for (int t = 0; t < 2; ++t) {
    expected += bytes8(3);
    for (const auto v : faces[t])
      expected += bytes32(v, false);
    for (const auto c : colors[t])
      expected += bytes8(c);
    expected += bytes32(m.mesh.labels[t], false);
    expected += bytes8(static_cast<std::uint8_t>(m.mesh.classes[t]));
  }
  EXPECT_TRUE(fileBytes(ply) == expected);

  expected = "# vtk DataFile Version 3.0\npcl_selective_seg segmented mesh\nBINARY\n"
             "DATASET POLYDATA\nPOINTS 4 float\n";
  for (const int p : order)
    for (const auto b : m.bits[p])
      expected += bytes32(b, true);
  expected += "\nPOLYGONS 2 8\n";
  for (const auto& f : faces) {
    expected += bytes32(3, true);
    for (const auto v : f)
      expected += bytes32(v, true);
  }
  expected += "\nCELL_DATA 2\nCOLOR_SCALARS colors 3\n";
  for (const auto& c : colors)
    for (const auto byte : c)
      expected += bytes8(byte);
  expected += "\nSCALARS label unsigned_int 1\nLOOKUP_TABLE default\n";
  expected += bytes32(2, true) + bytes32(1, true);
  expected += "\nSCALARS class unsigned_char 1\nLOOKUP_TABLE default\n";
  expected += bytes8(0) + bytes8(1) + "\n";
  EXPECT_TRUE(fileBytes(vtk) == expected);
}

// A mesh of several blocks of faces: the same bytes on one thread and on three, and
// PCL reads back every face.
TEST(MeshWriters, LargeMeshSameBytesForAnyThreadCount)
{
  // A grid of 400 x 400 points, two triangles per cell (318,402 faces: two blocks).
  const int side = 400;
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (int r = 0; r < side; ++r)
    for (int c = 0; c < side; ++c)
      cloud.push_back(pcl::PointXYZ(0.01f * c, 0.01f * r, 1.0f));
  SegmentedMesh mesh;
  for (int r = 0; r + 1 < side; ++r)
    for (int c = 0; c + 1 < side; ++c) {
      const int a = r * side + c;
      mesh.triangles.push_back({a, a + 1, a + side});
      mesh.triangles.push_back({a + 1, a + side + 1, a + side});
    }
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    mesh.labels.push_back(static_cast<std::uint32_t>(t % 97));
    mesh.classes.push_back(static_cast<TriangleClass>(t % 3));
  }
  const ScratchDir dir("selseg_writers_large");
  const std::string ply = dir.file("mesh.ply"), vtk = dir.file("mesh.vtk");
  std::map<std::string, std::string> one;
  for (const int threads : {1, 3}) {
    ASSERT_TRUE(selseg_apps::writeMeshPly(ply, cloud, mesh, threads));
    ASSERT_TRUE(selseg_apps::writeMeshVtk(vtk, cloud, mesh, threads));
    for (const auto& path : {ply, vtk}) {
      const std::string content = fileBytes(path);
      if (threads == 1)
        one[path] = content;
      else
        EXPECT_TRUE(content == one[path]) << path << " differs with 3 threads";
    }
  }
  pcl::PolygonMesh read;
  ASSERT_EQ(pcl::io::loadPLYFile(ply, read), 0);
  ASSERT_EQ(read.polygons.size(), mesh.triangles.size());
  ASSERT_EQ(read.cloud.width * read.cloud.height, cloud.size());
  pcl::PointCloud<pcl::PointXYZ> vertices;
  pcl::fromPCLPointCloud2(read.cloud, vertices);
  for (std::size_t t = 0; t < mesh.triangles.size(); t += 997)
    for (int i = 0; i < 3; ++i) {
      const auto v = read.polygons[t].vertices[i];
      ASSERT_EQ(vertices[v].getVector3fMap(),
                cloud[mesh.triangles[t][i]].getVector3fMap())
          << "face " << t << " corner " << i;
    }
}

// The JSON summary's segments: the numbers as the stream printed them (%.9g), in label
// order, the same text on one thread and on three (several blocks of segments).
TEST(SummaryJson, SegmentLinesKnownTextForAnyThreadCount)
{
  pcl::selective_seg::SegmentationResult r;
  for (std::uint32_t l = 1; l <= 10000; ++l) {
    pcl::selective_seg::Segment s;
    s.label = l;
    s.num_points = 5 + l;
    s.num_leaves = 2;
    s.area = 0.1 * l;
    s.normal = Eigen::Vector3f(0.1f, -0.5f, 1.0f);
    r.segments.push_back(s);
  }
  selseg_apps::RunInfo info;
  info.input = "scan \"1\".pcd";
  const ScratchDir dir("selseg_json");
  const std::string one = dir.file("one.json"), three = dir.file("three.json");
  ASSERT_TRUE(selseg_apps::writeSummaryJson(one, info, r, 1));
  ASSERT_TRUE(selseg_apps::writeSummaryJson(three, info, r, 3));
  const std::string text = fileBytes(one);
  EXPECT_TRUE(text == fileBytes(three));
  EXPECT_NE(text.find("\"input\": \"scan \\\"1\\\".pcd\""), std::string::npos);
  EXPECT_NE(
      text.find("\"segments\": [\n    {\"label\": 1, \"points\": 6, \"leaves\": 2, "
                "\"area_m2\": 0.1, \"normal\": [0.100000001, -0.5, 1]},\n"),
      std::string::npos);
  EXPECT_NE(text.find(",\n    {\"label\": 4097, \"points\": 4102, \"leaves\": 2, "
                      "\"area_m2\": 409.7, "),
            std::string::npos);
  const std::string last =
      "{\"label\": 10000, \"points\": 10005, \"leaves\": 2, "
      "\"area_m2\": 1000, \"normal\": [0.100000001, -0.5, 1]}\n  ]\n}\n";
  ASSERT_GE(text.size(), last.size());
  EXPECT_EQ(text.substr(text.size() - last.size()), last);
}

// A file name need not be UTF-8; the JSON files must be. Each ill-formed sequence of
// the input's name becomes one U+FFFD (the longest start of a valid sequence, or one
// byte), well-formed characters are kept, control characters escaped: the summary and
// the regions file hold the same valid string.
TEST(SummaryJson, InputNameIsValidUtf8)
{
  const std::string name = "a\xff"
                           "b\xc3\xa9"
                           "c\xe2\x82"
                           "d\xed\xa0\x80"
                           "e\xf0\x9f\x98\x80"
                           "f\x01\xc3";
  const std::string fffd = "\xef\xbf\xbd";
  const std::string expected = "\"input\": \"a" + fffd + "b\xc3\xa9" + "c" + fffd +
                               "d" + fffd + fffd + fffd + "e\xf0\x9f\x98\x80" +
                               "f\\u0001" + fffd + "\",";
  EXPECT_EQ(selseg_apps::jsonString("\xc0\xaf\xf5\x80\xf4\x90"),
            "\"" + fffd + fffd + fffd + fffd + fffd + fffd + "\"");
  selseg_apps::RunInfo info;
  info.input = name;
  const ScratchDir dir("selseg_json_utf8");
  ASSERT_TRUE(selseg_apps::writeSummaryJson(
      dir.file("summary.json"), info, pcl::selective_seg::SegmentationResult{}));
  ASSERT_TRUE(
      selseg_apps::writeRegionsJson(dir.file("regions.json"), name, {}, {}, {}));
  for (const char* file : {"summary.json", "regions.json"}) {
    const std::string text = fileBytes(dir.file(file));
    EXPECT_NE(text.find(expected), std::string::npos) << file << ": " << text;
  }
}

// The labeled cloud: PCL reads back the input's points, layout and viewpoint with the
// labels; the header is the one PCL's own writer makes; the same bytes on one thread
// and on three (several compressed chunks).
TEST(LabeledCloudWriter, PclReadsTheInputWithItsLabels)
{
  // An organized 400 x 300 cloud (1.9 MB of planes: two chunks) with invalid points.
  pcl::PointCloud<pcl::PointXYZ> cloud(400, 300);
  std::vector<std::uint32_t> labels(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const float u = static_cast<float>(i % 400), v = static_cast<float>(i / 400);
    cloud[i] = pcl::PointXYZ(0.01f * u, 0.02f * v, 1.0f + 0.001f * (u + v));
    labels[i] = static_cast<std::uint32_t>((i * 7919) % 1000);
    if (i % 37 == 0) {
      cloud[i].x = cloud[i].y = cloud[i].z = std::numeric_limits<float>::quiet_NaN();
      labels[i] = 0;
    }
  }
  cloud.is_dense = false;
  cloud.sensor_origin_ = Eigen::Vector4f(0.5f, -0.25f, 2.0f, 0.0f);
  cloud.sensor_orientation_ = Eigen::Quaternionf(0.5f, 0.5f, -0.5f, 0.5f);
  const ScratchDir dir("selseg_labels");
  const std::string one = dir.file("one.pcd"), three = dir.file("three.pcd");
  ASSERT_TRUE(selseg_apps::writeLabeledCloud(one, cloud, labels, 1));
  ASSERT_TRUE(selseg_apps::writeLabeledCloud(three, cloud, labels, 3));
  EXPECT_TRUE(fileBytes(one) == fileBytes(three));

  pcl::PointCloud<pcl::PointXYZL> read;
  ASSERT_EQ(pcl::io::loadPCDFile(one, read), 0);
  ASSERT_EQ(read.width, cloud.width);
  ASSERT_EQ(read.height, cloud.height);
  EXPECT_EQ(read.sensor_origin_, cloud.sensor_origin_);
  EXPECT_EQ(read.sensor_orientation_.coeffs(), cloud.sensor_orientation_.coeffs());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    ASSERT_EQ(std::memcmp(read[i].data, cloud[i].data, 12), 0) << i;
    ASSERT_EQ(read[i].label, labels[i]) << i;
  }

  // PCL's writer, on the same cloud: the same header up to the data.
  pcl::PointCloud<pcl::PointXYZL> labeled;
  pcl::copyPointCloud(cloud, labeled);
  for (std::size_t i = 0; i < cloud.size(); ++i)
    labeled[i].label = labels[i];
  const std::string pcl_file = dir.file("pcl.pcd");
  ASSERT_EQ(pcl::io::savePCDFileBinaryCompressed(pcl_file, labeled), 0);
  const auto header = [](const std::string& bytes) {
    return bytes.substr(0, bytes.find("DATA binary_compressed\n"));
  };
  const std::string ours = fileBytes(one);
  ASSERT_NE(ours.find("DATA binary_compressed\n"), std::string::npos);
  EXPECT_EQ(header(ours), header(fileBytes(pcl_file)));

  // Labels that do not match the cloud: nothing is claimed written.
  labels.pop_back();
  EXPECT_FALSE(selseg_apps::writeLabeledCloud(dir.file("bad.pcd"), cloud, labels));
}

int
main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  if (argc > 2) {
    tool = argv[1];
    scan = argv[2];
  }
  return RUN_ALL_TESTS();
}
