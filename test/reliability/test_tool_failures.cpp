/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// The tool on broken inputs and broken output locations: truncated or corrupt files,
// lying headers, wrong field types, unwritable folders, a full disk (a file size limit,
// RLIMIT_FSIZE, in the child). Each gives a message saying what is wrong, exit code 1
// (2 for usage errors), and no output: neither a partial file nor a changed old one.
// pcl_selective_seg_compare is checked on broken clouds and command lines too. A run
// ended by a signal while it writes leaves no temporary file.
// Arguments: the tool's path, the bundled scan, pcl_selective_seg_compare's path,
// pcl_selective_seg_simulate's path, then the fault-injection module's
// (fail_allocation.cpp).

#include <gtest/gtest.h>
#include <pcl/io/pcd_io.h>
#include <pcl/io/ply_io.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <cube_scene.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

std::string tool;     // NOLINT: set once in main()
std::string scan;     // NOLINT: set once in main()
std::string compare;  // NOLINT: set once in main(); pcl_selective_seg_compare
std::string simulate; // NOLINT: set once in main(); pcl_selective_seg_simulate
std::string fail_allocation; // NOLINT: set once in main(); fail_allocation.cpp's module

struct Outcome {
  int code = -1;        ///< exit code, -1 when killed by a signal
  std::string messages; ///< stdout and stderr
};

/** Run \a program with \a args, optionally under a file size limit [KiB]. */
Outcome
runProgram(const std::string& program,
           const std::string& args,
           long file_size_limit_kib = -1)
{
  std::string command = "'" + program + "' " + args;
  if (file_size_limit_kib >= 0)
    command = "bash -c \"ulimit -f " + std::to_string(file_size_limit_kib) +
              "; trap '' XFSZ; exec " + command + "\"";
  Outcome o;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe)
    return o;
  char buffer[4096];
  std::size_t n;
  while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0)
    o.messages.append(buffer, n);
  const int status = pclose(pipe);
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return o;
}

/** Run the tool with \a args, optionally under a file size limit [KiB]. */
Outcome
run(const std::string& args, long file_size_limit_kib = -1)
{
  return runProgram(tool, args, file_size_limit_kib);
}

std::string
shellQuoted(const fs::path& p)
{
  return "'" + p.string() + "'";
}

void
writeFile(const fs::path& path, const std::string& content)
{
  std::ofstream(path, std::ios::binary) << content;
}

std::string
readFile(const fs::path& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), {});
}

/** A 40 x 30 wall at 1 m, centred on the optical axis. */
pcl::PointCloud<pcl::PointXYZ>
wall()
{
  pcl::PointCloud<pcl::PointXYZ> cloud(40, 30);
  for (int r = 0; r < 30; ++r)
    for (int c = 0; c < 40; ++c)
      cloud.at(c, r) = pcl::PointXYZ(0.01f * (c - 20), 0.01f * (r - 15), 1.0f);
  return cloud;
}

/** A PCD header for the wall with the given field declarations. */
std::string
pcdHeader(const std::string& fields,
          const std::string& sizes,
          const std::string& types,
          const std::string& counts,
          std::size_t points,
          const std::string& data)
{
  std::ostringstream h;
  h << "# .PCD v0.7\nVERSION 0.7\nFIELDS " << fields << "\nSIZE " << sizes << "\nTYPE "
    << types << "\nCOUNT " << counts << "\nWIDTH " << points
    << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points << "\nDATA " << data
    << "\n";
  return h.str();
}

class ToolFailure : public ::testing::Test {
protected:
  void SetUp() override
  {
    if (tool.empty() || !fs::exists(tool) || !fs::exists(scan))
      GTEST_SKIP() << "tool or scan missing";
    // The process id: several builds may run this suite at once on one machine.
    dir =
        fs::temp_directory_path() /
        ("selseg_failure_" +
         std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
         "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir / "in");
    fs::create_directories(dir / "out");
  }
  void TearDown() override { fs::remove_all(dir); }
  /** Files in out/ (outputs, temporaries, leftovers). */
  std::vector<std::string> outputs() const
  {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir / "out"))
      names.push_back(e.path().filename().string());
    return names;
  }
  /** Every output option, into out/. */
  std::string allOutputs() const
  {
    const fs::path o = dir / "out";
    return " -o " + shellQuoted(o / "labels.pcd") + " -mesh_ply " +
           shellQuoted(o / "mesh.ply") + " -mesh_vtk " + shellQuoted(o / "mesh.vtk") +
           " -leaves " + shellQuoted(o / "leaves.pcd") + " -json " +
           shellQuoted(o / "summary.json");
  }
  /** The tool's labels file for \a input run with \a options, written to
   * out/labels.pcd, read into \a labeled and removed; false, with a failure recorded,
   * when the run or the read fails. */
  bool labeledBy(const fs::path& input,
                 const std::string& options,
                 pcl::PointCloud<pcl::PointXYZL>& labeled)
  {
    const fs::path labels = dir / "out" / "labels.pcd";
    const Outcome o =
        run(shellQuoted(input) + " " + options + " -o " + shellQuoted(labels));
    EXPECT_EQ(o.code, 0) << input << ": " << o.messages;
    const bool read =
        o.code == 0 && pcl::io::loadPCDFile(labels.string(), labeled) == 0;
    EXPECT_TRUE(read) << labels;
    fs::remove(labels);
    return read;
  }
  /** The tool must fail on \a input with exit code 1, say \a why, write nothing. */
  void expectRejected(const fs::path& input, const std::string& why)
  {
    const Outcome o = run(shellQuoted(input) + " -ignore_viewpoint" + allOutputs());
    EXPECT_EQ(o.code, 1) << input << ": " << o.messages;
    EXPECT_NE(o.messages.find(why), std::string::npos)
        << input << ": expected '" << why << "' in: " << o.messages;
    EXPECT_TRUE(outputs().empty()) << input;
  }
  fs::path dir;
};

} // namespace

TEST_F(ToolFailure, TruncatedFilesAreRejected)
{
  const auto cloud = wall();
  const fs::path in = dir / "in";
  pcl::io::savePCDFileBinary((in / "binary.pcd").string(), cloud);
  pcl::io::savePCDFileBinaryCompressed((in / "compressed.pcd").string(), cloud);
  pcl::io::savePCDFileASCII((in / "ascii.pcd").string(), cloud);
  pcl::io::savePLYFileBinary((in / "binary.ply").string(), cloud);
  pcl::io::savePLYFileASCII((in / "ascii.ply").string(), cloud);
  fs::copy_file(scan, in / "scan.pcd");
  for (const char* name : {"binary.pcd",
                           "compressed.pcd",
                           "ascii.pcd",
                           "binary.ply",
                           "ascii.ply",
                           "scan.pcd"}) {
    const std::string full = readFile(in / name);
    // Cut in the data (two thirds) and in the header (40 bytes).
    for (const std::size_t keep : {full.size() * 2 / 3, std::size_t(40)}) {
      writeFile(in / ("cut_" + std::to_string(keep) + "_" + name),
                full.substr(0, keep));
      expectRejected(in / ("cut_" + std::to_string(keep) + "_" + name), "cannot read");
    }
  }
}

TEST_F(ToolFailure, CorruptFilesAreRejected)
{
  const fs::path in = dir / "in";
  const std::string xyz = pcdHeader("x y z", "4 4 4", "F F F", "1 1 1", 3, "ascii");
  // The header promises more points than the data holds.
  writeFile(in / "short_ascii.pcd", xyz + "0 0 1\n1 0 1\n");
  expectRejected(in / "short_ascii.pcd", "cannot read");
  // A header claiming four billion points, with no data: no huge allocation.
  writeFile(in / "huge.pcd",
            pcdHeader("x y z", "4 4 4", "F F F", "1 1 1", 4000000000u, "binary"));
  expectRejected(in / "huge.pcd", "cannot read");
  writeFile(
      in / "huge_compressed.pcd",
      pcdHeader("x y z", "4 4 4", "F F F", "1 1 1", 4000000000u, "binary_compressed") +
          std::string("\x10\0\0\0\xff\xff\xff\x7f", 8) + std::string(16, 'A'));
  expectRejected(in / "huge_compressed.pcd", "cannot read");
  // Compressed data whose sizes disagree with the header.
  writeFile(in / "bad_compressed.pcd",
            pcdHeader("x y z", "4 4 4", "F F F", "1 1 1", 3, "binary_compressed") +
                std::string("\x04\0\0\0\x24\0\0\0garbage", 15));
  expectRejected(in / "bad_compressed.pcd", "cannot read");
  // Not a point cloud at all, under each extension.
  std::string noise(5000, '\0');
  for (std::size_t i = 0; i < noise.size(); ++i)
    noise[i] = static_cast<char>((i * 2654435761u) >> 13);
  for (const char* name : {"noise.pcd", "noise.ply", "noise.xyz"}) {
    writeFile(in / name, noise);
    expectRejected(in / name, "'");
  }
  for (const char* name : {"empty.pcd", "empty.ply", "empty.xyz"}) {
    writeFile(in / name, "");
    expectRejected(in / name, "'");
  }
  // ASCII PCD rows that PCL reads as zeros or ignores (with only a warning): a row
  // with too few values, a word, more rows than the header's points.
  writeFile(in / "short_row.pcd", xyz + "0 0 1\n1 0\n1 1 1\n");
  expectRejected(in / "short_row.pcd", "data row 2 holds 2 values");
  writeFile(in / "word_row.pcd", xyz + "0 0 1\n1 zero 1\n1 1 1\n");
  expectRejected(in / "word_row.pcd", "data row 2 holds '1 zero 1'");
  writeFile(in / "extra_row.pcd", xyz + "0 0 1\n1 0 1\n\n1 1 1\n2 2 1\n");
  expectRejected(in / "extra_row.pcd", "more rows than the header's 3 points");
  writeFile(in / "nan_row.pcd", xyz + "0 0 1\n NaN\tnan 1 \r\n\n1 1 1\n");
  // NaN in any case, tabs, a trailing carriage return and blank lines are PCL's too.
  const Outcome nan_row = run(shellQuoted(in / "nan_row.pcd") + " -ignore_viewpoint");
  EXPECT_EQ(nan_row.messages.find("data row"), std::string::npos) << nan_row.messages;
  // Text: a word among the numbers, a number beyond float's range.
  writeFile(in / "word.xyz", "0 0 1\n0.1 0 1\n0.1 zero 1\n");
  expectRejected(in / "word.xyz", "line 3");
  writeFile(in / "overflow.xyz", "0 0 1\n0.1 0 1e60\n");
  expectRejected(in / "overflow.xyz", "line 2");
  // A folder, and a missing file.
  expectRejected(in, "cannot");
  expectRejected(in / "missing.pcd", "cannot read");
}

// x y z stored as doubles are read as such, not left at zero; types that are not
// coordinates are refused with a message naming the field.
TEST_F(ToolFailure, FieldTypesAreCheckedOrConverted)
{
  const fs::path in = dir / "in";
  const auto cloud = wall();
  std::ostringstream doubles;
  doubles.precision(17);
  doubles << pcdHeader("x y z", "8 8 8", "F F F", "1 1 1", cloud.size(), "ascii");
  for (const auto& p : cloud)
    doubles << p.x << " " << p.y << " " << p.z << "\n";
  writeFile(in / "doubles.pcd", doubles.str());
  pcl::PointCloud<pcl::PointXYZL> labeled;
  ASSERT_TRUE(labeledBy(in / "doubles.pcd", "-ignore_viewpoint", labeled));
  ASSERT_EQ(labeled.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    ASSERT_EQ(labeled[i].getVector3fMap(), cloud[i].getVector3fMap()) << i;
    ASSERT_EQ(labeled[i].label, 1u) << i;
  }

  std::ostringstream bytes;
  bytes << pcdHeader("x y z", "1 1 1", "U U U", "1 1 1", cloud.size(), "ascii");
  for (std::size_t i = 0; i < cloud.size(); ++i)
    bytes << i % 7 << " " << i % 5 << " 1\n";
  writeFile(in / "bytes.pcd", bytes.str());
  expectRejected(in / "bytes.pcd", "field x");

  std::ostringstream vector_x;
  vector_x << pcdHeader("x y z", "4 4 4", "F F F", "2 1 1", cloud.size(), "ascii");
  for (std::size_t i = 0; i < cloud.size(); ++i)
    vector_x << "0 0 0 1\n";
  writeFile(in / "vector_x.pcd", vector_x.str());
  expectRejected(in / "vector_x.pcd", "field x");

  std::ostringstream no_z;
  no_z << pcdHeader("x y", "4 4", "F F", "1 1", cloud.size(), "ascii");
  for (std::size_t i = 0; i < cloud.size(); ++i)
    no_z << "0 0\n";
  writeFile(in / "no_z.pcd", no_z.str());
  expectRejected(in / "no_z.pcd", "no x, y and z");
}

TEST_F(ToolFailure, UnwritableLocationsLeaveNothing)
{
  writeFile(dir / "out" / "a_file", "not a folder");
  const std::string in = shellQuoted(scan) + " -ignore_viewpoint";
  const std::vector<std::string> targets = {
      (dir / "out" / "a_file" / "labels.pcd").string(),  // under a file: ENOTDIR
      (dir / "out" / "missing" / "labels.pcd").string(), // no such folder
      "/proc/selseg_labels.pcd",                         // a read-only file system
  };
  for (const auto& target : targets) {
    const Outcome o = run(in + " -json " + shellQuoted(dir / "out" / "summary.json") +
                          " -o '" + target + "'");
    EXPECT_EQ(o.code, 1) << target << ": " << o.messages;
    EXPECT_NE(o.messages.find("Cannot write"), std::string::npos) << o.messages;
    EXPECT_EQ(outputs(), std::vector<std::string>{"a_file"}) << target;
  }
  // An output that is an existing folder: refused before anything is replaced.
  fs::create_directories(dir / "out" / "folder.pcd");
  writeFile(dir / "out" / "summary.json", "old");
  const Outcome o = run(in + " -json " + shellQuoted(dir / "out" / "summary.json") +
                        " -o " + shellQuoted(dir / "out" / "folder.pcd"));
  EXPECT_EQ(o.code, 1) << o.messages;
  EXPECT_EQ(readFile(dir / "out" / "summary.json"), "old");
  EXPECT_TRUE(fs::is_directory(dir / "out" / "folder.pcd"));
  EXPECT_EQ(outputs().size(), 3u);
}

// An output path that exists and is not a regular file was replaced by the renamed
// temporary (a FIFO by a regular file, whose reader then waited for ever; as root, a
// device such as /dev/null). It is refused with exit 1, as a folder is. A symbolic link
// to a regular file stays a link: the file it names is replaced.
TEST_F(ToolFailure, OutputsThatAreNotRegularFilesAreRefused)
{
  const fs::path out = dir / "out";
  ASSERT_EQ(::mkfifo((out / "fifo.pcd").c_str(), 0600), 0);
  fs::create_symlink("/dev/null", out / "null.json");
  const std::string in = shellQuoted(scan) + " -ignore_viewpoint";
  Outcome o = run(in + " -o " + shellQuoted(out / "fifo.pcd"));
  EXPECT_EQ(o.code, 1) << o.messages;
  EXPECT_NE(o.messages.find("not a regular file"), std::string::npos) << o.messages;
  EXPECT_TRUE(fs::is_fifo(out / "fifo.pcd"));
  o = run(in + " -json " + shellQuoted(out / "null.json"));
  EXPECT_EQ(o.code, 1) << o.messages;
  EXPECT_NE(o.messages.find("not a regular file"), std::string::npos) << o.messages;
  EXPECT_TRUE(fs::is_symlink(out / "null.json"));
  EXPECT_EQ(fs::read_symlink(out / "null.json"), "/dev/null");
  EXPECT_EQ(outputs().size(), 2u); // no temporary left
  // Found before the scan is read, not after the segmentation.
  fs::create_directories(out / "folder.pcd");
  o = run(in + " -leaves " + shellQuoted(out / "folder.pcd"));
  EXPECT_EQ(o.code, 1) << o.messages;
  EXPECT_NE(o.messages.find("folder"), std::string::npos) << o.messages;
  EXPECT_EQ(o.messages.find("Loaded"), std::string::npos) << o.messages;
  fs::remove(out / "folder.pcd");

  // Links to a regular file in another folder (absolute), to a file not made yet
  // (relative, dangling) and to a link: each stays a link, its target is written.
  fs::create_directories(dir / "real");
  writeFile(dir / "real" / "labels.pcd", "old labels");
  fs::create_symlink(dir / "real" / "labels.pcd", out / "labels.pcd");
  fs::create_symlink("new.json", out / "summary.json");
  fs::create_symlink("summary.json", out / "again.json");
  fs::remove(out / "fifo.pcd");
  fs::remove(out / "null.json");
  o = run(in + " -o " + shellQuoted(out / "labels.pcd") + " -json " +
          shellQuoted(out / "again.json"));
  ASSERT_EQ(o.code, 0) << o.messages;
  EXPECT_TRUE(fs::is_symlink(out / "labels.pcd"));
  EXPECT_TRUE(fs::is_symlink(out / "summary.json"));
  EXPECT_TRUE(fs::is_symlink(out / "again.json"));
  pcl::PointCloud<pcl::PointXYZL> labeled;
  EXPECT_EQ(pcl::io::loadPCDFile((dir / "real" / "labels.pcd").string(), labeled), 0);
  EXPECT_GT(labeled.size(), 0u);
  EXPECT_NE(readFile(out / "new.json").find("\"segments\""), std::string::npos);
  std::size_t in_real = 0;
  for (const auto& e : fs::directory_iterator(dir / "real")) {
    static_cast<void>(e);
    ++in_real;
  }
  EXPECT_EQ(in_real, 1u); // no temporary left beside the target
  EXPECT_EQ(outputs().size(), 4u);
}

// A full disk: the child may write at most N KiB per file (bash's ulimit -f, SIGXFSZ
// ignored, so writes fail with EFBIG). Whatever output hits the limit, the run fails
// with a message and leaves no file; an old output of the same name is kept as it was.
TEST_F(ToolFailure, FullDiskLeavesNothing)
{
  writeFile(dir / "out" / "labels.pcd", "old labels");
  // (Not 0 KiB: LLVM's OpenMP runtime, in clang builds, then cannot create its
  // registration file in /dev/shm and aborts at start-up, before the tool runs.)
  for (const long limit : {4L, 16L, 600L, 2000L}) {
    const Outcome o =
        run(shellQuoted(scan) + " -ignore_viewpoint" + allOutputs(), limit);
    EXPECT_EQ(o.code, 1) << limit << " KiB: " << o.messages;
    EXPECT_NE(o.messages.find("free space"), std::string::npos) << o.messages;
    EXPECT_EQ(outputs(), std::vector<std::string>{"labels.pcd"}) << limit << " KiB";
    EXPECT_EQ(readFile(dir / "out" / "labels.pcd"), "old labels") << limit << " KiB";
  }
  // Without the limit the same command succeeds and replaces the old file.
  const Outcome o = run(shellQuoted(scan) + " -ignore_viewpoint" + allOutputs());
  ASSERT_EQ(o.code, 0) << o.messages;
  EXPECT_EQ(outputs().size(), 5u);
  EXPECT_NE(readFile(dir / "out" / "labels.pcd"), "old labels");
}

// Two outputs naming one file, or an output naming the input, would silently lose a
// result or the scan: usage errors.
TEST_F(ToolFailure, OutputsThatCollideAreUsageErrors)
{
  const fs::path labels = dir / "out" / "x.pcd";
  Outcome o = run(shellQuoted(scan) + " -ignore_viewpoint -o " + shellQuoted(labels) +
                  " -leaves " + shellQuoted(labels));
  EXPECT_EQ(o.code, 2) << o.messages;
  EXPECT_NE(o.messages.find("same file"), std::string::npos) << o.messages;
  const fs::path copy = dir / "in" / "scan.pcd";
  fs::copy_file(scan, copy);
  o = run(shellQuoted(copy) + " -ignore_viewpoint -o " +
          shellQuoted(dir / "in" / "." / "scan.pcd"));
  EXPECT_EQ(o.code, 2) << o.messages;
  EXPECT_NE(o.messages.find("input"), std::string::npos) << o.messages;
  EXPECT_EQ(readFile(copy), readFile(scan));
  EXPECT_TRUE(outputs().empty());
}

// -roi_json is an output like the others: it may name neither the input nor another
// output (it replaced the scan with the regions, or one of two JSON files was lost).
TEST_F(ToolFailure, RegionsFileThatCollidesIsAUsageError)
{
  const fs::path copy = dir / "in" / "scan.pcd";
  fs::copy_file(scan, copy);
  Outcome o =
      run(shellQuoted(copy) + " -ignore_viewpoint -roi_json " + shellQuoted(copy));
  EXPECT_EQ(o.code, 2) << o.messages;
  EXPECT_NE(o.messages.find("-roi_json names the input"), std::string::npos)
      << o.messages;
  EXPECT_TRUE(readFile(copy) == readFile(scan)) << "the input was changed";
  const fs::path json = dir / "out" / "x.json";
  o = run(shellQuoted(copy) + " -ignore_viewpoint -json " + shellQuoted(json) +
          " -roi_json " + shellQuoted(json));
  EXPECT_EQ(o.code, 2) << o.messages;
  EXPECT_NE(o.messages.find("-json and -roi_json name the same file"),
            std::string::npos)
      << o.messages;
  EXPECT_TRUE(outputs().empty());
}

// PCL's PLY reader takes `obj_info num_cols N` / `num_rows N` (atoi) as the cloud's
// layout and sizes its data by them; a value that does not match the vertex count made
// it write past its data and abort on an assertion (exit 134). Found by fuzzing.
TEST_F(ToolFailure, PlyLayoutMustMatchTheVertices)
{
  const fs::path in = dir / "in";
  pcl::io::savePLYFileBinary((in / "organized.ply").string(), wall()); // 40 x 30
  std::string good = readFile(in / "organized.ply");
  const std::string after = "comment PCL generated\n";
  ASSERT_NE(good.find(after), std::string::npos) << good.substr(0, 300);
  good.insert(good.find(after) + after.size(),
              "obj_info num_cols 40\nobj_info num_rows 30\n");
  writeFile(in / "organized.ply", good);
  // With a layout that matches its vertices, the file reads.
  const Outcome ok = run(shellQuoted(in / "organized.ply") + " -ignore_viewpoint");
  EXPECT_EQ(ok.code, 0) << ok.messages;
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  const struct {
    const char* name;
    std::string content;
  } cases[] = {
      {"rows_word.ply", replaced("obj_info num_rows 30", "obj_info num_rows t 1")},
      {"rows_zero.ply", replaced("obj_info num_rows 30", "obj_info num_rows 0")},
      {"rows_wrong.ply", replaced("obj_info num_rows 30", "obj_info num_rows 29")},
      {"cols_only.ply", replaced("obj_info num_rows 30", "comment no rows")},
  };
  for (const auto& c : cases) {
    writeFile(in / c.name, c.content);
    expectRejected(in / c.name, "cannot read");
  }
  // PCL's own writer leaves NaN points out and declares the organized size anyway (40
  // x 30 over 1,199 vertices): read as one row of the vertices it holds.
  auto holed = wall();
  holed.at(5, 5).x = std::numeric_limits<float>::quiet_NaN();
  pcl::PLYWriter().write((in / "holed.ply").string(), holed, true, false);
  ASSERT_NE(readFile(in / "holed.ply").find("obj_info num_rows 30"), std::string::npos);
  pcl::PointCloud<pcl::PointXYZL> out;
  ASSERT_TRUE(labeledBy(in / "holed.ply", "-ignore_viewpoint", out));
  EXPECT_EQ(out.size(), holed.size() - 1);
  EXPECT_EQ(out.height, 1u);
}

// PCL's PLY reader makes its colour field at `red` and writes it at `blue`: colours in
// another order or incomplete wrote over the coordinates or aborted the process on an
// assertion (exit 134). Found by review: they are refused; red green blue alpha reads.
TEST_F(ToolFailure, PlyColoursInAnotherOrderAreRefused)
{
  const fs::path in = dir / "in";
  const auto cloud = wall();
  const auto ply = [&](const std::vector<std::string>& colours) {
    std::ostringstream f;
    f.precision(9); // float's digits: the coordinates read back exactly
    f << "ply\nformat ascii 1.0\nelement vertex " << cloud.size()
      << "\nproperty float x\nproperty float y\nproperty float z\n";
    for (const auto& c : colours)
      f << "property uchar " << c << "\n";
    f << "property float confidence\nend_header\n";
    for (const auto& p : cloud) {
      f << p.x << " " << p.y << " " << p.z;
      for (std::size_t k = 0; k < colours.size(); ++k)
        f << " " << 10 * (k + 1);
      f << " 0.5\n";
    }
    return f.str();
  };
  writeFile(in / "rgba.ply", ply({"red", "green", "blue", "alpha"}));
  pcl::PointCloud<pcl::PointXYZL> out;
  ASSERT_TRUE(labeledBy(in / "rgba.ply", "-ignore_viewpoint", out));
  ASSERT_EQ(out.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i)
    ASSERT_EQ(out[i].getVector3fMap(), cloud[i].getVector3fMap()) << i;
  const std::vector<std::vector<std::string>> refused = {
      {"blue", "green", "red"},
      {"blue"},
      {"green", "blue"},
      {"red", "blue", "green"},
      {"alpha"},
      {"red", "green", "blue", "red", "green", "blue"}};
  for (std::size_t k = 0; k < refused.size(); ++k) {
    const fs::path file = in / ("colours" + std::to_string(k) + ".ply");
    writeFile(file, ply(refused[k]));
    expectRejected(file, "vertex colours");
  }
}

// A coordinate field given twice: PCL reads the first, which may not be the one meant.
TEST_F(ToolFailure, CoordinateFieldGivenTwiceIsRefused)
{
  const fs::path in = dir / "in";
  const auto cloud = wall();
  std::ostringstream f;
  f << pcdHeader("x y z z", "4 4 4 4", "F F F F", "1 1 1 1", cloud.size(), "ascii");
  for (const auto& p : cloud)
    f << p.x << " " << p.y << " " << p.z << " " << 2 * p.z << "\n";
  writeFile(in / "twice.pcd", f.str());
  expectRejected(in / "twice.pcd", "more than one field z");
}

// Coordinates stored as doubles far from the origin (a georeferenced scan) lose their
// last digits in float: points 1 cm apart at 4,000 km are rounded by 25 cm. Refused
// with what to do; the same points near the origin are read, also with a pair of
// near-duplicates that float makes one (registered scans hold such pairs).
TEST_F(ToolFailure, DoublesThatFloatDistortsAreRefused)
{
  const fs::path in = dir / "in";
  const auto cloud = wall();
  for (const double offset : {0.0, 4.0e6}) {
    std::ostringstream f;
    f.precision(17);
    f << pcdHeader("x y z", "8 8 8", "F F F", "1 1 1", cloud.size() + 1, "ascii");
    for (const auto& p : cloud)
      f << offset + p.x << " " << offset + p.y << " " << p.z << "\n";
    f << offset + cloud[0].x + 1e-12 << " " << offset + cloud[0].y << " " << cloud[0].z
      << "\n";
    const fs::path file = in / ("offset" + std::to_string(offset > 0) + ".pcd");
    writeFile(file, f.str());
    if (offset == 0.0) {
      const Outcome o = run(shellQuoted(file) + " -ignore_viewpoint");
      EXPECT_EQ(o.code, 0) << o.messages;
    } else
      expectRejected(file, "more than a tenth of the points' spacing");
  }
}

// -unit_scale scales the file's VIEWPOINT with the points: a scan in centimetres with
// its sensor 50 cm in front of the origin reads as one in metres, sensor 0.5 m away,
// and the labels file keeps the scaled VIEWPOINT.
TEST_F(ToolFailure, UnitScaleScalesTheViewpoint)
{
  const fs::path in = dir / "in";
  auto cloud = wall();
  for (auto& p : cloud)
    p.getVector3fMap() *= 100.0f; // cm, the wall at 100 cm
  cloud.sensor_origin_ = Eigen::Vector4f(0.0f, 0.0f, 50.0f, 0.0f);
  pcl::io::savePCDFileBinary((in / "cm.pcd").string(), cloud);
  pcl::PointCloud<pcl::PointXYZL> out;
  ASSERT_TRUE(labeledBy(in / "cm.pcd", "-unit_scale 0.01", out));
  EXPECT_NEAR(out.sensor_origin_.z(), 0.5f, 1e-6f);
  EXPECT_NEAR(out[0].z, 1.0f, 1e-6f);
  EXPECT_GT(out[0].label, 0u);
}

// Options whose values are not what they need are usage errors (exit 2) that name the
// option, before anything is read or written.
TEST_F(ToolFailure, MalformedOptionValuesAreUsageErrors)
{
  const std::string input = shellQuoted(scan) + " ";
  const fs::path labels = dir / "out" / "labels.pcd";
  const struct {
    std::string args;
    const char* why;
  } cases[] = {
      {"-sensor_origin a,b,c", "-sensor_origin needs 3 comma-separated"},
      {"-sensor_origin 1e-3,x,0", "-sensor_origin needs 3 comma-separated"},
      {"-sensor_orientation 1x,0,0,0", "-sensor_orientation needs 4"},
      {"-sensor_origin 1e39,0,0", "within float's range"},
      {"-sensor_origin 0,0,5 -ignore_viewpoint", "not both"},
      {"-ignore_viewpoint -o ''", "-o needs a file name"},
      {"-ignore_viewpoint -json ''", "-json needs a file name"},
      {"-o -ignore_viewpoint", "not the option '-ignore_viewpoint'"},
      {"-ignore_viewpoint -json -o " + shellQuoted(labels), "not the option '-o'"},
      {"-ignore_viewpoint -threads 1.5", "-threads needs a whole number"},
      {"-ignore_viewpoint -merge_deg 5x", "-merge_deg needs a number, not '5x'"},
      {"-ignore_viewpoint -merge_deg 1e400", "-merge_deg 1e400 is beyond"},
      {"-ignore_viewpoint -roi_leaf_sigma_deg -1", "-roi_leaf_sigma_deg needs 0"},
  };
  for (const auto& c : cases) {
    const Outcome o = run(input + c.args);
    EXPECT_EQ(o.code, 2) << c.args << ": " << o.messages;
    EXPECT_NE(o.messages.find(c.why), std::string::npos)
        << c.args << ": expected '" << c.why << "' in: " << o.messages;
  }
  EXPECT_TRUE(outputs().empty());
  EXPECT_FALSE(fs::exists("-ignore_viewpoint"));
}

// Text scans: nan and inf are points like the others (counted, left unlabeled), a word
// glued to a number is not a number.
TEST_F(ToolFailure, TextCoordinatesAreReadWhole)
{
  const fs::path in = dir / "in";
  std::ostringstream f;
  for (const auto& p : wall())
    f << p.x << " " << p.y << " " << p.z << "\n";
  writeFile(in / "nan.xyz", f.str() + "nan 0 1\n0 inf 1\n");
  const Outcome o = run(shellQuoted(in / "nan.xyz"));
  EXPECT_EQ(o.code, 0) << o.messages;
  EXPECT_NE(o.messages.find("2 non-finite"), std::string::npos) << o.messages;
  writeFile(in / "suffix.xyz", f.str() + "0.05 0 2abc\n");
  expectRejected(in / "suffix.xyz", "'2abc' is not a number");
  writeFile(in / "range.xyz", f.str() + "0.05 0 1e400\n");
  expectRejected(in / "range.xyz", "beyond float's range");
  // ASCII PLY: PCL's reader made a word a NaN point; refused with its line. A short
  // element before the vertices is skipped; nan stays a point.
  const auto ply = [&](const std::string& last_vertex) {
    std::ostringstream p;
    const auto cloud = wall();
    p << "ply\nformat ascii 1.0\nelement note 1\nproperty float a\nelement vertex "
      << cloud.size() + 1
      << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n7\n";
    for (const auto& q : cloud)
      p << q.x << " " << q.y << " " << q.z << "\n";
    return p.str() + last_vertex + "\n";
  };
  writeFile(in / "nan.ply", ply("nan 0 1"));
  const Outcome n = run(shellQuoted(in / "nan.ply"));
  EXPECT_EQ(n.code, 0) << n.messages;
  EXPECT_NE(n.messages.find("1 non-finite"), std::string::npos) << n.messages;
  writeFile(in / "word.ply", ply("abc 0.05 2.0"));
  expectRejected(in / "word.ply", "vertex 1200 (line 1202 after the header) has 'abc'");
  writeFile(in / "short.ply", ply("0.05 2.0"));
  expectRejected(in / "short.ply", "fewer than its 3 values");
}

// A lying header must not make the tool allocate what the header claims.
TEST_F(ToolFailure, LyingHeadersUseBoundedMemory)
{
  writeFile(dir / "in" / "huge.pcd",
            pcdHeader("x y z", "4 4 4", "F F F", "1 1 1", 4000000000u, "ascii") +
                "0 0 1\n");
  const Outcome o = run(shellQuoted(dir / "in" / "huge.pcd") + " -ignore_viewpoint");
  EXPECT_EQ(o.code, 1) << o.messages;
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  EXPECT_LT(usage.ru_maxrss, 1L << 20) << "KiB"; // below 1 GiB
}

// PCL's PCD header reader takes keywords by prefix and reads on after DATA. Each file
// below makes it allocate 80 points of 26,843,552 bytes (2.1 GB, zero-filled) before it
// sees that the data is missing: the tool must refuse the header before PCL reads it,
// with its own message, not run out of memory.
TEST_F(ToolFailure, HeadersPclReadsDifferentlyAreRefused)
{
  const std::string start = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n";
  const std::string organized = "WIDTH 10\nHEIGHT 8\nPOINTS 80\n";
  const std::string data(960, '\0'); // 80 points of x, y, z
  const struct {
    const char* name;
    std::string content;
    const char* message;
  } cases[] = {
      // A COUNT line hidden in the binary data: PCL reads it, and POINTS after it.
      {"after_data.pcd",
       start + "COUNT 1 1 1\n" + organized +
           "DATA binary\nCOUNT 1 1 6710886\nPOINTS 80\n" + data,
       "follows DATA"},
      // "COUNTS" is a COUNT line to PCL.
      {"prefix.pcd",
       start + "COUNTS 1 1 6710886\n" + organized + "DATA binary\n" + data,
       "COUNT 6710886"},
      // A form feed splits values for >> but not for PCL's count of them.
      {"form_feed.pcd",
       start + "COUNT 1 1\f6710886 1\n" + organized + "DATA binary\n" + data,
       "control characters"},
      // A line PCL does not know ends its header: DATA would never be seen.
      {"unknown_line.pcd",
       start + "COUNT 1 1 1\nRANGE 0 1\n" + organized + "DATA binary\n" + data,
       "no PCD header line"},
  };
  for (const auto& c : cases) {
    writeFile(dir / "in" / c.name, c.content);
    const Outcome o = run(shellQuoted(dir / "in" / c.name) + " -ignore_viewpoint");
    EXPECT_EQ(o.code, 1) << c.name << ": " << o.messages;
    EXPECT_NE(o.messages.find("header is corrupt"), std::string::npos)
        << c.name << ": " << o.messages;
    EXPECT_NE(o.messages.find(c.message), std::string::npos)
        << c.name << ": " << o.messages;
  }
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  EXPECT_LT(usage.ru_maxrss, 1L << 20) << "KiB"; // below 1 GiB
}

// pcl_selective_seg_compare reads its clouds with the tool's checked reader: a file
// that is empty, noise or declares four billion points is a message and exit 1 (PCL's
// reader crashed on the first two, and the third aborted on std::bad_alloc), and -o
// writes nothing. A cloud without a labeled finite point is refused too (PCL's
// segmenters crashed on a cloud without a finite point; they were then reported as
// failed, with rows of NaN scores).
TEST_F(ToolFailure, CompareToolRejectsBrokenClouds)
{
  if (compare.empty() || !fs::exists(compare))
    GTEST_SKIP() << "pcl_selective_seg_compare missing";
  const fs::path in = dir / "in";
  const std::string table = " -o " + shellQuoted(dir / "out" / "table.md");
  std::string noise(5000, '\0');
  for (std::size_t i = 0; i < noise.size(); ++i)
    noise[i] = static_cast<char>((i * 2654435761u) >> 13);
  writeFile(in / "noise.pcd", noise);
  writeFile(in / "empty.pcd", "");
  const std::string xyzl =
      pcdHeader("x y z label", "4 4 4 4", "F F F U", "1 1 1 1", 4000000000u, "binary");
  writeFile(in / "huge.pcd", xyzl + std::string(300 - xyzl.size() % 300, '\0'));
  writeFile(in / "no_label.pcd",
            pcdHeader("x y z", "4 4 4", "F F F", "1 1 1", 1, "ascii") + "0 0 1\n");
  for (const char* name : {"noise.pcd", "empty.pcd", "huge.pcd", "no_label.pcd"}) {
    const Outcome o = runProgram(compare, shellQuoted(in / name) + table);
    EXPECT_EQ(o.code, 1) << name << ": " << o.messages;
    EXPECT_NE(o.messages.find("cannot read '" + (in / name).string() + "'"),
              std::string::npos)
        << name << ": " << o.messages;
    EXPECT_TRUE(outputs().empty()) << name;
  }

  // A cloud without a labeled finite point (all NaN here, or every label 0) has no
  // ground truth to compare with: exit 1 (it gave rows of NaN scores).
  std::ostringstream nan, zero;
  nan << pcdHeader("x y z label", "4 4 4 4", "F F F U", "1 1 1 1", 100, "ascii");
  zero << pcdHeader("x y z label", "4 4 4 4", "F F F U", "1 1 1 1", 100, "ascii");
  for (int i = 0; i < 100; ++i) {
    nan << "nan nan nan 1\n";
    zero << 0.01 * (i % 10) << " " << 0.01 * (i / 10) << " 1 0\n";
  }
  writeFile(in / "nan.pcd", nan.str());
  writeFile(in / "zero.pcd", zero.str());
  for (const char* name : {"nan.pcd", "zero.pcd"}) {
    const Outcome o = runProgram(compare, shellQuoted(in / name) + table);
    EXPECT_EQ(o.code, 1) << o.messages;
    EXPECT_NE(o.messages.find("has no ground-truth label"), std::string::npos)
        << o.messages;
    EXPECT_TRUE(outputs().empty()) << name;
  }
}

// Found by review (session 26): PCL's integral-image normals crashed (SIGSEGV) on an
// organized cloud under 10 pixels wide or high, and PCL's octree aborted on a cloud
// spanning 2e7 m (one far outlier) in Supervoxel+LCCP: those methods are now reported
// as failed, the others run.
TEST_F(ToolFailure, CompareToolReportsWhatPclCannotRunAsFailed)
{
  if (compare.empty() || !fs::exists(compare))
    GTEST_SKIP() << "pcl_selective_seg_compare missing";
  const fs::path in = dir / "in";
  std::ostringstream small;
  std::string header =
      pcdHeader("x y z label", "4 4 4 4", "F F F U", "1 1 1 1", 81, "ascii");
  header.replace(header.find("WIDTH 81\nHEIGHT 1"), 17, "WIDTH 9\nHEIGHT 9");
  small << header;
  for (int i = 0; i < 81; ++i)
    small << 0.01 * (i % 9) << " " << 0.01 * (i / 9) << " 1 " << 1 + (i % 9 > 4)
          << "\n";
  writeFile(in / "small.pcd", small.str());
  std::ostringstream outlier;
  outlier << pcdHeader("x y z label", "4 4 4 4", "F F F U", "1 1 1 1", 401, "ascii");
  for (int i = 0; i < 400; ++i)
    outlier << 0.01 * (i % 20) << " " << 0.01 * (i / 20) << " 1 1\n";
  outlier << "0 0 2e7 2\n";
  writeFile(in / "outlier.pcd", outlier.str());
  const std::string table = dir / "out" / "table.md";
  const Outcome o =
      runProgram(compare,
                 shellQuoted(in / "small.pcd") + " " + shellQuoted(in / "outlier.pcd") +
                     " -o " + shellQuoted(table));
  ASSERT_EQ(o.code, 0) << o.messages;
  const std::string text = readFile(table);
  EXPECT_NE(text.find("| small.pcd | OrganizedMultiPlane | failed"), std::string::npos)
      << text;
  EXPECT_NE(text.find("| outlier.pcd | Supervoxel+LCCP | failed"), std::string::npos)
      << text;
  EXPECT_NE(text.find("| outlier.pcd | RegionGrowing | 0."), std::string::npos) << text;
  // A table in a folder that does not exist is refused before any cloud is read.
  const Outcome missing = runProgram(compare,
                                     shellQuoted(in / "small.pcd") + " -o " +
                                         shellQuoted(dir / "no" / "t.md"));
  EXPECT_EQ(missing.code, 1);
  EXPECT_NE(missing.messages.find("check that the folder exists"), std::string::npos)
      << missing.messages;
  EXPECT_EQ(missing.messages.find("OrganizedMultiPlane"), std::string::npos)
      << missing.messages;
}

// Its command line: unknown options, inputs that are not .pcd, -o twice or naming an
// input are usage errors (they were ignored); a table that cannot be written
// completely is exit 1 and no file (it was put in place unchecked).
TEST_F(ToolFailure, CompareToolChecksItsCommandLineAndTable)
{
  if (compare.empty() || !fs::exists(compare))
    GTEST_SKIP() << "pcl_selective_seg_compare missing";
  const fs::path in = dir / "in";
  std::ostringstream cloud;
  cloud << pcdHeader("x y z label", "4 4 4 4", "F F F U", "1 1 1 1", 100, "ascii");
  for (int i = 0; i < 100; ++i)
    cloud << 0.01 * (i % 10) << " " << 0.01 * (i / 10) << " 1 1\n";
  writeFile(in / "wall.pcd", cloud.str());
  const std::string wall = shellQuoted(in / "wall.pcd");
  const std::string table = shellQuoted(dir / "out" / "table.md");
  const struct {
    std::string args;
    const char* message;
  } usage[] = {
      {wall + " -bogus", "Unknown option '-bogus'"},
      {wall + " " + shellQuoted(in / "wall.xyz"), "is not a .pcd file"},
      {wall + " -o " + table + " -o " + table, "-o is given more than once"},
      {wall + " -o " + wall, "names the input"},
      {"-o " + table, "at least one"},
  };
  for (const auto& u : usage) {
    const Outcome o = runProgram(compare, u.args);
    EXPECT_EQ(o.code, 2) << u.args << ": " << o.messages;
    EXPECT_NE(o.messages.find(u.message), std::string::npos)
        << u.args << ": " << o.messages;
  }
  EXPECT_TRUE(outputs().empty());
  // Each cloud adds about 1.5 KB of rows: four are more than 1 KiB may hold.
  const std::string four = wall + " " + wall + " " + wall + " " + wall;
  Outcome o = runProgram(compare, four + " -o " + table, 1);
  EXPECT_EQ(o.code, 1) << o.messages;
  EXPECT_NE(o.messages.find("free space"), std::string::npos) << o.messages;
  EXPECT_TRUE(outputs().empty());
  o = runProgram(compare, four + " -o " + table);
  EXPECT_EQ(o.code, 0) << o.messages;
  EXPECT_GT(readFile(dir / "out" / "table.md").size(), 1024u);
  EXPECT_EQ(outputs().size(), 1u);
  // One ground-truth region has no boundary to recall: "-", not nan.
  const std::string written = readFile(dir / "out" / "table.md");
  EXPECT_EQ(written.find("nan"), std::string::npos) << written;
  EXPECT_NE(written.find("% | - |"), std::string::npos) << written;
}

// A run ended by SIGTERM, SIGINT or SIGHUP while it wrote its outputs left its
// temporaries (OUT.tmpN, 1.4 MB seen). The tool now removes them and ends by the same
// signal (exit status 128 + its number). Each signal is sent once a temporary exists;
// a run that ends before one is seen is not counted, and the test is skipped when no
// run was caught writing.
/** Runs \a args (the program first) with the default signal actions and its output
 * to /dev/null, and sends \a sig once a file with ".tmp" in its name appears in
 * \a folder. \return whether the signal was sent before the run ended; \a status is
 * the run's wait status. A run of more than 120 s is killed and fails the test. */
bool
signalWhileWriting(const std::vector<std::string>& args,
                   const fs::path& folder,
                   int sig,
                   int& status)
{
  const auto temporaryExists = [&] {
    for (const auto& e : fs::directory_iterator(folder))
      if (e.path().filename().string().find(".tmp") != std::string::npos)
        return true;
    return false;
  };
  std::vector<char*> argv;
  for (const auto& a : args)
    argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ADD_FAILURE() << "fork failed";
    return false;
  }
  if (pid == 0) {
    // The default actions, whatever this process inherited (a shell's background
    // job ignores SIGINT).
    for (const int s : {SIGTERM, SIGINT, SIGHUP})
      std::signal(s, SIG_DFL);
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::dup2(null, 2);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  status = 0;
  bool ended = false, seen = false;
  const auto start = std::chrono::steady_clock::now();
  while (!ended && !seen) {
    ended = ::waitpid(pid, &status, WNOHANG) == pid;
    seen = !ended && temporaryExists();
    if (!ended && !seen) {
      if (std::chrono::steady_clock::now() - start > std::chrono::seconds(120)) {
        ::kill(pid, SIGKILL);
        ::waitpid(pid, &status, 0);
        ADD_FAILURE() << "the tool ran for more than 120 s";
        return false;
      }
      ::usleep(500);
    }
  }
  if (!seen)
    return false;
  ::kill(pid, sig);
  EXPECT_EQ(::waitpid(pid, &status, 0), pid);
  return !(WIFEXITED(status) && WEXITSTATUS(status) == 0);
}

TEST_F(ToolFailure, SignalsLeaveNoTemporaries)
{
  if (simulate.empty() || !fs::exists(simulate))
    GTEST_SKIP() << "pcl_selective_seg_simulate missing";
  // About a million points: the outputs take a few hundred milliseconds to write.
  const fs::path big = dir / "in" / "door.pcd";
  const Outcome made =
      runProgram(simulate, "-scene door -density 20 -o " + shellQuoted(big));
  ASSERT_EQ(made.code, 0) << made.messages;
  const fs::path out = dir / "out";
  const std::string labels = (out / "labels.pcd").string();
  const std::string mesh = (out / "mesh.ply").string();
  int caught = 0;
  for (const int sig : {SIGTERM, SIGINT, SIGHUP}) {
    for (const auto& e : fs::directory_iterator(out))
      fs::remove_all(e.path());
    int status = 0;
    if (!signalWhileWriting(
            {tool, big.string(), "-o", labels, "-mesh_ply", mesh}, out, sig, status))
      continue; // it ended before the signal: nothing to check
    ++caught;
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == sig)
        << "signal " << sig << ": status " << status << ", expected exit status "
        << 128 + sig;
    EXPECT_TRUE(outputs().empty())
        << "signal " << sig << ": " << outputs().size() << " files left, the first "
        << (outputs().empty() ? "" : outputs()[0]);
  }
  if (caught == 0)
    GTEST_SKIP() << "every run ended before a temporary file was seen";
}

// The simulator wrote "OUT.tmp" and renamed it: a signal during the write left it (a
// 261 MB file in the review of session 28). It now stages its output as the other
// tools do.
TEST_F(ToolFailure, SimulatorSignalLeavesNoTemporary)
{
  if (simulate.empty() || !fs::exists(simulate))
    GTEST_SKIP() << "pcl_selective_seg_simulate missing";
  const fs::path out = dir / "out";
  int caught = 0;
  for (int attempt = 0; attempt < 3 && caught == 0; ++attempt) {
    int status = 0;
    if (!signalWhileWriting({simulate,
                             "-scene",
                             "door",
                             "-density",
                             "20",
                             "-o",
                             (out / "door.pcd").string()},
                            out,
                            SIGTERM,
                            status))
      continue;
    ++caught;
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM)
        << "status " << status;
    EXPECT_TRUE(outputs().empty()) << outputs().size() << " files left, the first "
                                   << (outputs().empty() ? "" : outputs()[0]);
  }
  if (caught == 0)
    GTEST_SKIP() << "every run ended before a temporary file was seen";
}

// Out of memory at an allocation after main() starts (the options, reading, the
// pipeline on both threads, the regions of interest, the outputs): the tool exits 1
// with a message and leaves nothing, or succeeds with every output when the failed
// allocation did not matter. Before main() the shared libraries' static initialisers
// allocate (VTK's, PCL's); no program can report a failure there. The module's
// operator new stands in front of the sanitizers' allocators: not in their run.
TEST_F(ToolFailure, OutOfMemoryAfterStartIsReported)
{
  if (fail_allocation.empty() || !fs::exists(fail_allocation))
    GTEST_SKIP() << "the fault-injection module is missing";
  const auto labeled = selseg_test::cubeScan(4000, 5);
  pcl::PointCloud<pcl::PointXYZ> cube;
  for (const auto& p : *labeled)
    cube.push_back(pcl::PointXYZ(p.x, p.y, p.z));
  const fs::path in = dir / "in" / "cube.pcd";
  ASSERT_EQ(pcl::io::savePCDFileBinary(in.string(), cube), 0);
  const std::string args =
      shellQuoted(in) + " -ignore_viewpoint -threads 2" + allOutputs() + " -roi_json " +
      shellQuoted(dir / "out" / "roi.json") + " -roi_max_regions 5";
  const auto withModule = [&](const std::string& setting) {
    return runProgram("env",
                      setting + " LD_PRELOAD=" + shellQuoted(fail_allocation) + " " +
                          shellQuoted(tool) + " " + args);
  };
  const fs::path count_file = dir / "in" / "count.txt";
  const Outcome counted =
      withModule("SELSEG_COUNT_ALLOCATIONS=" + shellQuoted(count_file));
  ASSERT_EQ(counted.code, 0) << counted.messages;
  const std::size_t num_outputs = outputs().size();
  ASSERT_EQ(num_outputs, 6u);
  long total = 0;
  std::ifstream(count_file) >> total;
  ASSERT_GT(total, 1000);
  fs::remove_all(dir / "out");
  fs::create_directories(dir / "out");
  int reported = 0;
  for (long k = 0; k < 60; ++k) {
    const long n = k * total / 60;
    const Outcome o = withModule("SELSEG_FAIL_ALLOCATION=" + std::to_string(n));
    if (o.code == 0) {
      EXPECT_EQ(outputs().size(), num_outputs) << "allocation " << n;
      fs::remove_all(dir / "out");
      fs::create_directories(dir / "out");
      continue;
    }
    ASSERT_EQ(o.code, 1) << "allocation " << n << " of " << total << ": " << o.messages;
    EXPECT_NE(o.messages.find("memory"), std::string::npos)
        << "allocation " << n << ": " << o.messages;
    EXPECT_TRUE(outputs().empty()) << "allocation " << n;
    ++reported;
  }
  EXPECT_GT(reported, 50);
}

int
main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  if (argc > 2) {
    tool = argv[1];
    scan = argv[2];
  }
  if (argc > 3)
    compare = argv[3];
  if (argc > 4)
    simulate = argv[4];
  if (argc > 5)
    fail_allocation = argv[5];
  return RUN_ALL_TESTS();
}
