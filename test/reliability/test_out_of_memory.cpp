/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// Out of memory (docs/reliability.md, "Out of memory"): the Nth allocation of an
// extract(), an update() or a computeRegionsOfInterest() throws std::bad_alloc, for N
// spread over every allocation of the call, on whichever thread makes it. Each trial
// runs in a child process of its own (the parent never runs an OpenMP region, so that
// every child starts its own thread pool); the reference results come from one child,
// through a pipe. A trial must end in one of two ways: the call succeeds with the
// result of a run without the failure; or it returns false with its outputs cleared,
// the parameters and the input as they were, and the segmenter still works (update()
// refuses, extract() gives the result of a run without the failure). Anything else (a
// signal, std::terminate included; a hang; a wrong result; a changed state; an
// exception out of the call) fails the test.

#include <pcl_selective_seg/regions_of_interest.h>
#include <pcl_selective_seg/selective_segmentation.h>

#include <gtest/gtest.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <vector>

#include "replaced_operator_new.h"
#include <cube_scene.h>
#include <sys/wait.h>
#include <unistd.h>

namespace {

std::atomic<long> g_countdown{-1}; ///< allocations left before one fails; < 0: none fails
std::atomic<long> g_count{0};      ///< allocations so far

} // namespace

void*
selsegTestAllocate(std::size_t n, std::size_t alignment)
{
  g_count.fetch_add(1, std::memory_order_relaxed);
  if (g_countdown.load(std::memory_order_relaxed) >= 0 && g_countdown.fetch_sub(1) == 0)
    throw std::bad_alloc();
  return selsegTestMalloc(n, alignment);
}

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using Seg = pcl::selective_seg::SelectiveSegmentation<pcl::PointXYZ>;

/** Exit codes of a trial. */
enum Outcome : int {
  kSucceeded = 0,
  kRefusedCleanly = 3,
  kWrongResult = 4,
  kBrokenAfter = 5,
  kStateChanged = 6,
  kSetupFailed = 8
};

struct Scans {
  Cloud::Ptr first = pcl::make_shared<Cloud>(); ///< four points in five
  Cloud::Ptr rest = pcl::make_shared<Cloud>();  ///< the fifth
  Cloud::Ptr both = pcl::make_shared<Cloud>();  ///< first, then rest
  Scans()
  {
    const auto scan = selseg_test::cubeScan(4000, 5);
    for (std::size_t i = 0; i < scan->size(); ++i) {
      const auto& p = (*scan)[i];
      ((i % 5 == 4) ? rest : first)->push_back(pcl::PointXYZ(p.x, p.y, p.z));
    }
    *both = *first;
    *both += *rest;
  }
};

/** A segmenter on two threads that has segmented \a cloud; \a options: with every
 * option that takes another path through the stages switched away from its default. */
bool
prepare(Seg& seg, const Cloud::Ptr& cloud, bool options = false)
{
  auto p = seg.getParameters();
  p.num_threads = 2;
  if (options) {
    using namespace pcl::selective_seg;
    p.projection = ViewProjection::Panoramic; // the periodic triangulation
    p.normal_rings = 2;
    p.point_normal_triangles = PointNormalTriangles::NotEdgeOn;
    p.edge_triangle_normal = EdgeTriangleNormal::VertexMean;
    p.normal_spread_frame = NormalSpreadFrame::MeanNormal;
    p.segment_normal_weight = SegmentNormalWeight::Area;
    p.merge_with = MergeWith::Segments;
  }
  seg.setParameters(p);
  seg.setInputCloud(cloud);
  std::vector<pcl::PointIndices> clusters;
  return seg.extract(clusters);
}

/** What a call gives without a failure, what a segmenter must give after a failed
 * call (extract() on the union), and the call's allocations. */
struct Reference {
  long allocations = 0;
  std::vector<std::uint32_t> call_labels, union_labels;
  std::vector<double> regions; ///< fingerprint() of the regions of interest
};

/** The regions' windows, priorities and sizes, in their order. */
std::vector<double>
fingerprint(const std::vector<pcl::selective_seg::RegionOfInterest>& regions)
{
  std::vector<double> f;
  for (const auto& r : regions)
    f.insert(f.end(),
             {r.theta_min,
              r.theta_max,
              r.phi_min,
              r.phi_max,
              r.priority,
              r.suggested_step,
              static_cast<double>(r.num_points),
              static_cast<double>(r.estimated_points)});
  return f;
}

/** The calls under test. */
enum class Call { Extract, ExtractWithOptions, Update, RegionsOfInterest };

/** The call: extract() of both, update() of first with rest, or the regions of
 * interest of a segmenter that has segmented both. */
bool
call(Seg& seg,
     const Scans& s,
     Call what,
     std::vector<pcl::PointIndices>& clusters,
     std::vector<pcl::selective_seg::RegionOfInterest>& regions)
{
  switch (what) {
  case Call::Update:
    return seg.update(*s.rest, clusters);
  case Call::RegionsOfInterest:
    return pcl::selective_seg::computeRegionsOfInterest(
        seg, pcl::selective_seg::RegionOfInterestParameters(), regions);
  case Call::Extract:
  case Call::ExtractWithOptions:
    break;
  }
  seg.setInputCloud(s.both);
  return seg.extract(clusters);
}

/** The segmenter a trial starts from. */
bool
prepareFor(Seg& seg, const Scans& s, Call what)
{
  return prepare(seg,
                 what == Call::RegionsOfInterest ? s.both : s.first,
                 what == Call::ExtractWithOptions);
}

/** In a child. */
Reference
reference(const Scans& s, Call what)
{
  Reference r;
  Seg seg;
  if (!prepareFor(seg, s, what))
    std::_Exit(kSetupFailed);
  std::vector<pcl::PointIndices> clusters;
  std::vector<pcl::selective_seg::RegionOfInterest> regions;
  const long before = g_count.load();
  if (!call(seg, s, what, clusters, regions))
    std::_Exit(kSetupFailed);
  r.allocations = g_count.load() - before;
  r.call_labels = seg.getResult().labels;
  r.regions = fingerprint(regions);
  Seg fresh;
  if (!prepare(fresh, s.both, what == Call::ExtractWithOptions))
    std::_Exit(kSetupFailed);
  r.union_labels = fresh.getResult().labels;
  return r;
}

/** In a child: fail the nth allocation of the call, then check the state. */
int
trial(const Scans& s, const Reference& ref, Call what, long n)
{
  Seg seg;
  if (!prepareFor(seg, s, what))
    return kSetupFailed;
  const auto params = seg.getParameters();
  std::vector<pcl::PointIndices> clusters;
  std::vector<pcl::selective_seg::RegionOfInterest> regions;
  g_countdown = n;
  bool ok = false;
  try {
    ok = call(seg, s, what, clusters, regions);
  } catch (...) {
    return kWrongResult; // the library lets no exception out
  }
  g_countdown = -1;
  if (what == Call::RegionsOfInterest) {
    if (ok)
      return fingerprint(regions) == ref.regions ? kSucceeded : kWrongResult;
    if (!regions.empty() || seg.getResult().labels != ref.call_labels)
      return kStateChanged;
    if (!call(seg, s, what, clusters, regions))
      return kBrokenAfter;
    return fingerprint(regions) == ref.regions ? kRefusedCleanly : kBrokenAfter;
  }
  if (ok)
    return seg.getResult().labels == ref.call_labels ? kSucceeded : kWrongResult;
  if (!clusters.empty() || !seg.getResult().labels.empty() ||
      seg.getParameters().min_voxel_size != params.min_voxel_size)
    return kStateChanged;
  if (what == Call::Update) {
    if (seg.getInputCloud() != s.first)
      return kStateChanged;
    if (seg.update(*s.rest, clusters)) // nothing to fold into
      return kStateChanged;
    seg.setInputCloud(s.both);
  }
  if (!seg.extract(clusters))
    return kBrokenAfter;
  return seg.getResult().labels == ref.union_labels ? kRefusedCleanly : kBrokenAfter;
}

/** Runs f in a child process with a time limit; its wait status. */
template <typename F>
int
inChild(F f)
{
  const pid_t pid = fork();
  if (pid == 0) {
    alarm(120);
    // A failed call's PCL_ERROR, once per trial: not wanted in the log.
    if (FILE* null = std::freopen("/dev/null", "w", stderr); !null)
      std::_Exit(kSetupFailed);
    std::_Exit(f());
  }
  int status = 0;
  waitpid(pid, &status, 0);
  return status;
}

bool
writeAll(int fd, const void* data, std::size_t size)
{
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t k = write(fd, p, size);
    if (k <= 0)
      return false;
    p += k;
    size -= static_cast<std::size_t>(k);
  }
  return true;
}

bool
readAll(int fd, void* data, std::size_t size)
{
  char* p = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t k = read(fd, p, size);
    if (k <= 0)
      return false;
    p += k;
    size -= static_cast<std::size_t>(k);
  }
  return true;
}

template <typename T>
bool
writeVector(int fd, const std::vector<T>& v)
{
  const std::size_t n = v.size();
  return writeAll(fd, &n, sizeof n) && writeAll(fd, v.data(), n * sizeof(T));
}

template <typename T>
bool
readVector(int fd, std::vector<T>& v)
{
  std::size_t n = 0;
  if (!readAll(fd, &n, sizeof n) || n > (std::size_t{1} << 28))
    return false;
  v.resize(n);
  return readAll(fd, v.data(), n * sizeof(T));
}

void
sweep(Call what)
{
  const Scans scans;
  // The reference, from a child (the parent runs no OpenMP region). The parent reads
  // while the child writes, so that no pipe buffer limits the size.
  int pipe_fd[2];
  ASSERT_EQ(pipe(pipe_fd), 0);
  const pid_t pid = fork();
  if (pid == 0) {
    close(pipe_fd[0]);
    const Reference ref = reference(scans, what);
    const bool sent = writeAll(pipe_fd[1], &ref.allocations, sizeof ref.allocations) &&
                      writeVector(pipe_fd[1], ref.call_labels) &&
                      writeVector(pipe_fd[1], ref.union_labels) &&
                      writeVector(pipe_fd[1], ref.regions);
    std::_Exit(sent ? 0 : kSetupFailed);
  }
  close(pipe_fd[1]);
  Reference ref;
  const bool received = readAll(pipe_fd[0], &ref.allocations, sizeof ref.allocations) &&
                        readVector(pipe_fd[0], ref.call_labels) &&
                        readVector(pipe_fd[0], ref.union_labels) &&
                        readVector(pipe_fd[0], ref.regions);
  close(pipe_fd[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0 && received);
  ASSERT_GT(ref.allocations, 100);
  if (what == Call::RegionsOfInterest) {
    ASSERT_FALSE(ref.regions.empty()); // the scene has regions to find
  }
  const long step = std::max(1L, ref.allocations / 150);
  int refused = 0, succeeded = 0;
  for (long n = 0; n < ref.allocations; n += step) {
    const int s = inChild([&] { return trial(scans, ref, what, n); });
    ASSERT_FALSE(WIFSIGNALED(s)) << "allocation " << n << " of " << ref.allocations
                                 << ": signal " << WTERMSIG(s);
    ASSERT_TRUE(WIFEXITED(s));
    const int code = WEXITSTATUS(s);
    ASSERT_TRUE(code == kSucceeded || code == kRefusedCleanly)
        << "allocation " << n << " of " << ref.allocations << ": outcome " << code;
    refused += code == kRefusedCleanly;
    succeeded += code == kSucceeded;
  }
  EXPECT_GT(refused, 0);
  std::printf("%ld allocations, every %ld-th failed: %d reported, %d without effect\n",
              ref.allocations,
              step,
              refused,
              succeeded);
}

} // namespace

TEST(OutOfMemory, ExtractReportsIt)
{
  sweep(Call::Extract);
}

TEST(OutOfMemory, ExtractWithOtherOptionsReportsIt)
{
  sweep(Call::ExtractWithOptions);
}

TEST(OutOfMemory, UpdateReportsIt)
{
  sweep(Call::Update);
}

TEST(OutOfMemory, RegionsOfInterestReportIt)
{
  sweep(Call::RegionsOfInterest);
}

int
main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  return RUN_ALL_TESTS();
}
