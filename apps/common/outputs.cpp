/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

#define PCL_NO_PRECOMPILE
#include "outputs.h"

#include <pcl_selective_seg/impl/parallel_exceptions.hpp>

#include <pcl/console/print.h>
#include <pcl/io/lzf.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_types.h>
#include <pcl/register_point_struct.h>

#include <atomic>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <type_traits>

#include "segment_colors.h"
#include "segmentation_options.h"
#include <unistd.h>

namespace selseg_apps {
namespace {

using pcl::selective_seg::SegmentedMesh;

/** The vertices the triangles use, numbered densely in the order of their first use. */
struct CompactMesh {
  std::vector<pcl::index_t> points;  ///< input index of each output vertex
  std::vector<std::uint32_t> number; ///< output number of each input point used

  /** Output numbers of the corners of triangle \a t. */
  std::array<std::uint32_t, 3> face(const SegmentedMesh& mesh, std::size_t t) const
  {
    const auto& c = mesh.triangles[t];
    return {number[c[0]], number[c[1]], number[c[2]]};
  }
};

CompactMesh
compact(const SegmentedMesh& mesh, std::size_t num_points)
{
  constexpr auto kUnused = std::numeric_limits<std::uint32_t>::max();
  CompactMesh out;
  out.number.assign(num_points, kUnused);
  out.points.reserve(num_points);
  for (const auto& triangle : mesh.triangles)
    for (const pcl::index_t p : triangle) {
      std::uint32_t& n = out.number[static_cast<std::size_t>(p)];
      if (n == kUnused) {
        n = static_cast<std::uint32_t>(out.points.size());
        out.points.push_back(p);
      }
    }
  return out;
}

/** Stores \a value at \a out in little- or big-endian byte order, whatever the host's
 * order, and returns the next byte. */
template <bool kBigEndian, typename T>
char*
store(char* out, T value)
{
  static_assert(std::is_arithmetic<T>::value, "numbers only");
  using Bits = std::conditional_t<
      sizeof(T) == 1,
      std::uint8_t,
      std::conditional_t<
          sizeof(T) == 2,
          std::uint16_t,
          std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>>>;
  Bits bits;
  std::memcpy(&bits, &value, sizeof(T));
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    const std::size_t shift = 8 * (kBigEndian ? sizeof(T) - 1 - i : i);
    out[i] = static_cast<char>((bits >> shift) & 0xffu);
  }
  return out + sizeof(T);
}

template <typename T>
char*
putLittle(char* out, T value)
{
  return store<false>(out, value);
}

template <typename T>
char*
putBig(char* out, T value)
{
  return store<true>(out, value);
}

/** Writes \a count records of \a size bytes each, record i made by fill(i, its first
 * byte): a block of records at a time, filled on \a threads threads (the bytes do not
 * depend on them), then written in one call. */
template <typename Fill>
void
writeRecords(std::ostream& out,
             std::size_t count,
             std::size_t size,
             int threads,
             const Fill& fill)
{
  const std::size_t per_block = std::max<std::size_t>(1, (std::size_t{1} << 20) / size);
  std::vector<char> block(std::min(count, per_block) * size);
  for (std::size_t first = 0; first < count && out; first += per_block) {
    const auto n = static_cast<std::ptrdiff_t>(std::min(per_block, count - first));
#ifdef _OPENMP
#pragma omp parallel for num_threads(std::max(1, threads))                             \
    schedule(static) if (n >= 16384)
#endif
    for (std::ptrdiff_t i = 0; i < n; ++i)
      fill(first + static_cast<std::size_t>(i), block.data() + i * size);
    out.write(block.data(), static_cast<std::streamsize>(n) * size);
  }
  static_cast<void>(threads); // without OpenMP
}

/** Items [0, count), each made by make(item, slot) on one of up to \a threads threads
 * into its slot (0 .. threads - 1), a batch of one item per thread at a time; then
 * write(slot) takes the batch's slots in item order and returns false to stop. Output
 * in order, made in parallel, with memory for one item per thread. */
template <typename Make, typename Write>
void
inOrderBatches(std::size_t count, int threads, const Make& make, const Write& write)
{
  const int width = std::max(1, threads);
  const auto batch = static_cast<std::size_t>(width);
  for (std::size_t first = 0; first < count; first += batch) {
    const auto n = static_cast<std::ptrdiff_t>(std::min(batch, count - first));
    pcl::selective_seg::detail::ParallelExceptions errors; // made items allocate
#ifdef _OPENMP
#pragma omp parallel for num_threads(width) schedule(static, 1) if (n > 1)
#endif
    for (std::ptrdiff_t k = 0; k < n; ++k)
      errors.run([&] {
        make(first + static_cast<std::size_t>(k), static_cast<std::size_t>(k));
      });
    errors.rethrow();
    for (std::ptrdiff_t k = 0; k < n; ++k)
      if (!write(static_cast<std::size_t>(k)))
        return;
  }
}

/** The colour of every label's interior triangles (segmentColor()), looked up instead
 * of computed per triangle. */
std::vector<Rgb>
labelColors(const SegmentedMesh& mesh)
{
  std::uint32_t max_label = 0;
  for (const auto l : mesh.labels)
    max_label = std::max(max_label, l);
  return pcl::selective_seg::segmentColors(max_label);
}

/** triangleColor() of triangle \a t, an interior one's from the table of
 * labelColors(). */
Rgb
faceColor(const SegmentedMesh& mesh, const std::vector<Rgb>& colors, std::size_t t)
{
  return mesh.classes[t] == pcl::selective_seg::TriangleClass::Interior
             ? colors[mesh.labels[t]]
             : triangleColor(mesh.labels[t], mesh.classes[t]);
}

// The temporaries a signal removes (OutputTransaction): a fixed array of C strings, so
// that the handler neither allocates nor locks. An entry's state is kFree, kFilling
// (its path being written) or kStaged; the handler reads only kStaged ones.
constexpr int kFree = 0, kFilling = 1, kStaged = 2;
constexpr std::size_t kSignalSlots = 128;
constexpr std::size_t kSignalPathMax = 4096; // with its terminating 0
constexpr char kBackupSuffix[] = ".old";     // commit()'s hard links to old files
static_assert(std::atomic<int>::is_always_lock_free, "the handler reads the states");

struct SignalSlot {
  std::atomic<int> state{kFree};
  char path[kSignalPathMax];
};
SignalSlot signal_slots[kSignalSlots]; // NOLINT: shared with the signal handler

/** Removes every staged temporary and its backup link, then raises \a sig again with
 * the default action. Async-signal-safe: unlink(), signal() and raise() only. */
extern "C" void
removeTemporariesAndRaise(int sig)
{
  for (auto& slot : signal_slots) {
    if (slot.state.load(std::memory_order_acquire) != kStaged)
      continue;
    ::unlink(slot.path);
    char backup[kSignalPathMax + sizeof kBackupSuffix];
    std::size_t n = 0;
    for (; slot.path[n] != '\0'; ++n)
      backup[n] = slot.path[n];
    for (const char c : kBackupSuffix) // with its terminating 0
      backup[n++] = c;
    ::unlink(backup);
  }
  std::signal(sig, SIG_DFL);
  std::raise(sig); // blocked in the handler: delivered when it returns
}

/** Installs removeTemporariesAndRaise() for SIGTERM, SIGINT and SIGHUP where the action
 * is the default one, once. */
void
installSignalHandler()
{
  static bool installed = false;
  if (installed)
    return;
  installed = true;
  const int signals[] = {SIGTERM, SIGINT, SIGHUP};
  struct sigaction action {};
  action.sa_handler = removeTemporariesAndRaise;
  sigemptyset(&action.sa_mask);
  for (const int sig : signals) // one at a time: no second signal during the removal
    sigaddset(&action.sa_mask, sig);
  for (const int sig : signals) {
    struct sigaction old {};
    if (::sigaction(sig, nullptr, &old) == 0 && !(old.sa_flags & SA_SIGINFO) &&
        old.sa_handler == SIG_DFL)
      ::sigaction(sig, &action, nullptr);
  }
}

/** An entry of the signal handler holding \a path, or -1 when none is free or the path
 * is too long. */
int
takeSignalSlot(const std::string& path)
{
  if (path.size() + 1 > kSignalPathMax)
    return -1;
  for (std::size_t i = 0; i < kSignalSlots; ++i) {
    int expected = kFree;
    if (!signal_slots[i].state.compare_exchange_strong(expected, kFilling))
      continue;
    std::memcpy(signal_slots[i].path, path.c_str(), path.size() + 1);
    signal_slots[i].state.store(kStaged, std::memory_order_release);
    return static_cast<int>(i);
  }
  return -1;
}

/** The length of the well-formed UTF-8 sequence at \a s[i] (Unicode's table 3-7), or
 * the negated length of its longest start that some well-formed sequence has (at least
 * 1): what one U+FFFD replaces. */
int
utf8Sequence(const std::string& s, std::size_t i)
{
  const auto byte = [&](std::size_t k) {
    return k < s.size() ? static_cast<unsigned char>(s[k]) : 0u;
  };
  const unsigned b = byte(i);
  if (b < 0x80)
    return 1;
  int length = 0;
  unsigned lo = 0x80, hi = 0xbf; // the range of the second byte
  if (b >= 0xc2 && b <= 0xdf)
    length = 2;
  else if (b >= 0xe0 && b <= 0xef) {
    length = 3;
    lo = b == 0xe0 ? 0xa0 : 0x80;
    hi = b == 0xed ? 0x9f : 0xbf;
  } else if (b >= 0xf0 && b <= 0xf4) {
    length = 4;
    lo = b == 0xf0 ? 0x90 : 0x80;
    hi = b == 0xf4 ? 0x8f : 0xbf;
  } else
    return -1;
  for (int k = 1; k < length; ++k) {
    const unsigned c = byte(i + static_cast<std::size_t>(k));
    if (k == 1 ? c < lo || c > hi : c < 0x80 || c > 0xbf)
      return -k;
  }
  return length;
}

} // namespace

std::string
jsonString(const std::string& s)
{
  std::ostringstream out;
  out << '"';
  for (std::size_t i = 0; i < s.size();) {
    const char c = s[i];
    const int length = utf8Sequence(s, i);
    if (length < 0) {
      out << "\xef\xbf\xbd"; // U+FFFD
      i += static_cast<std::size_t>(-length);
      continue;
    }
    if (c == '"' || c == '\\')
      out << '\\' << c;
    else if (static_cast<unsigned char>(c) < 0x20)
      out << "\\u" << std::hex << std::setw(4) << std::setfill('0') << int(c)
          << std::dec;
    else
      out.write(s.data() + i, length);
    i += static_cast<std::size_t>(length);
  }
  out << '"';
  return out.str();
}

bool
samePath(const std::string& a, const std::string& b)
{
  std::error_code ec_a, ec_b;
  const auto ca = std::filesystem::weakly_canonical(a, ec_a);
  const auto cb = std::filesystem::weakly_canonical(b, ec_b);
  return !ec_a && !ec_b ? ca == cb : a == b;
}

OutputTransaction::~OutputTransaction()
{
  if (!committed_)
    for (const auto& f : files_)
      std::remove(f.temporary.c_str());
  releaseSignalSlots();
}

void
OutputTransaction::releaseSignalSlots()
{
  for (auto& f : files_)
    if (f.signal_slot >= 0) {
      signal_slots[f.signal_slot].state.store(kFree, std::memory_order_release);
      f.signal_slot = -1;
    }
}

std::string
OutputTransaction::stage(const std::string& final_path)
{
  namespace fs = std::filesystem;
  std::error_code ec;
  // The link's target, also when it does not exist yet (the output then creates it);
  // a chain of links is followed to its end, a loop left to fail when written.
  fs::path target = final_path;
  for (int hops = 0; hops < 40 && fs::is_symlink(target, ec); ++hops) {
    const fs::path next = fs::read_symlink(target, ec);
    if (ec)
      break;
    target =
        next.is_absolute() ? next : (target.parent_path() / next).lexically_normal();
  }
  const std::string temporary =
      target.string() + ".tmp" + std::to_string(files_.size());
  // In the signal handler's array before the caller opens the file.
  installSignalHandler();
  files_.push_back({temporary, target.string(), final_path, takeSignalSlot(temporary)});
  return files_.back().temporary;
}

bool
OutputTransaction::check(std::string& error) const
{
  namespace fs = std::filesystem;
  std::error_code ec;
  for (const auto& f : files_) {
    const fs::file_status status = fs::status(f.target, ec);
    if (fs::is_directory(status)) {
      error = "cannot write '" + f.given + "': it is a folder; give a file name";
      return false;
    }
    if (fs::exists(status) && !fs::is_regular_file(status)) {
      error = "cannot write '" + f.given + "'" +
              (f.target != f.given ? " (a link to '" + f.target + "')" : "") +
              ": it is not a regular file (a device, a FIFO or a socket), which the "
              "output would replace; give a file name";
      return false;
    }
  }
  return true;
}

bool
outputWritable(const std::string& path, std::string& error)
{
  OutputTransaction probe; // removes the probe file
  const std::string temporary = probe.stage(path);
  if (!probe.check(error))
    return false;
  if (!std::ofstream(temporary, std::ios::binary)) {
    error =
        "Cannot write '" + path + "': check that the folder exists and is writable.";
    return false;
  }
  return true;
}

bool
OutputTransaction::commit(std::string& error)
{
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!check(error))
    return false;
  // Old files of the same names are kept as hard links until every rename succeeded,
  // so that a failure part way restores them: all outputs change, or none.
  std::vector<std::string> backups(files_.size());
  for (std::size_t i = 0; i < files_.size(); ++i) {
    if (!fs::exists(files_[i].target, ec))
      continue;
    const std::string backup = files_[i].temporary + kBackupSuffix;
    std::remove(backup.c_str());
    if (::link(files_[i].target.c_str(), backup.c_str()) == 0)
      backups[i] = backup;
  }
  for (std::size_t i = 0; i < files_.size(); ++i)
    if (std::rename(files_[i].temporary.c_str(), files_[i].target.c_str()) != 0) {
      error = "cannot rename '" + files_[i].temporary + "' to '" + files_[i].target +
              "': " + std::strerror(errno);
      for (std::size_t j = 0; j < i; ++j)
        if (backups[j].empty())
          std::remove(files_[j].target.c_str());
        else
          std::rename(backups[j].c_str(), files_[j].target.c_str());
      for (std::size_t j = i; j < files_.size(); ++j)
        if (!backups[j].empty())
          std::remove(backups[j].c_str());
      return false;
    }
  for (const auto& b : backups)
    if (!b.empty())
      std::remove(b.c_str());
  committed_ = true;
  releaseSignalSlots();
  return true;
}

bool
writeLabeledCloud(const std::string& path,
                  const pcl::PointCloud<pcl::PointXYZ>& cloud,
                  const std::vector<std::uint32_t>& labels,
                  int threads)
{
  const std::size_t n = cloud.size();
  const std::size_t data_size = 16 * n; // the planes x, y, z, label
  if (labels.size() != n)
    return false;
  if (data_size > std::numeric_limits<std::uint32_t>::max()) {
    PCL_ERROR("The labeled cloud has %zu points: a binary_compressed PCD holds at most "
              "%zu (its data sizes are 32-bit). Write the mesh instead (-mesh_ply), or "
              "segment a part of the cloud.\n",
              n,
              static_cast<std::size_t>(std::numeric_limits<std::uint32_t>::max() / 16));
    return false;
  }
  // PCL's header for x y z label with the input's width, height and viewpoint, made for
  // a cloud of that shape without points; only its POINTS line depends on them.
  pcl::PointCloud<pcl::PointXYZL> shape;
  shape.width = cloud.width;
  shape.height = cloud.height;
  shape.sensor_origin_ = cloud.sensor_origin_;
  shape.sensor_orientation_ = cloud.sensor_orientation_;
  std::string header = pcl::PCDWriter::generateHeader(shape);
  const std::string no_points = "POINTS 0\n";
  if (header.size() < no_points.size() ||
      header.compare(header.size() - no_points.size(), no_points.size(), no_points) !=
          0)
    return false;
  header.resize(header.size() - no_points.size());
  header += "POINTS " + std::to_string(n) + "\nDATA binary_compressed\n";

  // The data: the planes as PCL lays them out, in chunks of kChunk bytes, each
  // compressed on its own (a concatenation of LZF streams is the LZF stream of the
  // concatenated data) on the threads, a batch at a time, and written in order. The
  // chunks do not depend on the thread count, so neither do the bytes.
  constexpr std::size_t kChunk = std::size_t{1} << 20;
  const std::size_t num_chunks = (data_size + kChunk - 1) / kChunk;
  const auto slots = static_cast<std::size_t>(std::max(1, threads));
  const std::size_t chunk_bytes = std::min(kChunk, data_size);
  std::vector<std::vector<char>> in(slots, std::vector<char>(chunk_bytes));
  std::vector<std::vector<char>> packed(
      slots, std::vector<char>(chunk_bytes + chunk_bytes / 2 + 16));
  std::vector<unsigned int> packed_size(slots);
  const auto fill = [&](std::size_t chunk, char* out) {
    // Byte offsets are multiples of 4: whole values.
    const std::size_t first = chunk * kChunk / 4;
    const std::size_t end = std::min(data_size, (chunk + 1) * kChunk) / 4;
    std::size_t plane = first / n, i = first % n;
    for (std::size_t e = first; e < end; ++e, out += 4) {
      if (plane < 3)
        std::memcpy(out, &cloud[i].data[plane], 4);
      else
        std::memcpy(out, &labels[i], 4);
      if (++i == n) {
        i = 0;
        ++plane;
      }
    }
    return (end - first) * 4;
  };
  std::ofstream out(path, std::ios::binary);
  out << header;
  const auto sizes_at = out.tellp();
  const std::uint32_t uncompressed = static_cast<std::uint32_t>(data_size);
  std::uint32_t compressed = 0;
  out.write(reinterpret_cast<const char*>(&compressed), 4);
  out.write(reinterpret_cast<const char*>(&uncompressed), 4);
  bool ok = true;
  inOrderBatches(
      num_chunks,
      threads,
      [&](std::size_t chunk, std::size_t k) {
        const std::size_t length = fill(chunk, in[k].data());
        packed_size[k] = pcl::lzfCompress(in[k].data(),
                                          static_cast<unsigned int>(length),
                                          packed[k].data(),
                                          static_cast<unsigned int>(packed[k].size()));
      },
      [&](std::size_t k) {
        ok = packed_size[k] > 0 && std::uint64_t{compressed} + packed_size[k] <=
                                       std::numeric_limits<std::uint32_t>::max();
        compressed += packed_size[k];
        out.write(packed[k].data(), packed_size[k]);
        return ok && static_cast<bool>(out);
      });
  out.seekp(sizes_at);
  out.write(reinterpret_cast<const char*>(&compressed), 4);
  out.close();
  return ok && static_cast<bool>(out);
}

bool
writeMeshPly(const std::string& path,
             const pcl::PointCloud<pcl::PointXYZ>& cloud,
             const SegmentedMesh& mesh,
             int threads)
{
  const CompactMesh m = compact(mesh, cloud.size());
  const std::vector<Rgb> colors = labelColors(mesh);
  std::ofstream out(path, std::ios::binary);
  out << "ply\nformat binary_little_endian 1.0\n"
      << "comment pcl_selective_seg segmented mesh: edge triangles white\n"
      << "element vertex " << m.points.size() << "\n"
      << "property float x\nproperty float y\nproperty float z\n"
      << "element face " << mesh.triangles.size() << "\n"
      << "property list uchar int vertex_indices\n"
      << "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      << "property uint label\nproperty uchar class\nend_header\n";
  writeRecords(out, m.points.size(), 12, threads, [&](std::size_t v, char* p) {
    for (int k = 0; k < 3; ++k)
      p = putLittle(p, cloud[m.points[v]].data[k]);
  });
  // Per face: 3, its vertices, red, green, blue, label, class.
  writeRecords(out, mesh.triangles.size(), 21, threads, [&](std::size_t t, char* p) {
    p = putLittle<std::uint8_t>(p, 3);
    for (const auto v : m.face(mesh, t))
      p = putLittle<std::int32_t>(p, static_cast<std::int32_t>(v));
    for (const auto c : faceColor(mesh, colors, t))
      p = putLittle(p, c);
    p = putLittle<std::uint32_t>(p, mesh.labels[t]);
    putLittle<std::uint8_t>(p, static_cast<std::uint8_t>(mesh.classes[t]));
  });
  out.close();
  return static_cast<bool>(out);
}

bool
writeMeshVtk(const std::string& path,
             const pcl::PointCloud<pcl::PointXYZ>& cloud,
             const SegmentedMesh& mesh,
             int threads)
{
  const CompactMesh m = compact(mesh, cloud.size());
  const std::vector<Rgb> colors = labelColors(mesh);
  const std::size_t n = mesh.triangles.size();
  std::ofstream out(path, std::ios::binary);
  out << "# vtk DataFile Version 3.0\npcl_selective_seg segmented mesh\nBINARY\n"
      << "DATASET POLYDATA\nPOINTS " << m.points.size() << " float\n";
  writeRecords(out, m.points.size(), 12, threads, [&](std::size_t v, char* p) {
    for (int k = 0; k < 3; ++k)
      p = putBig(p, cloud[m.points[v]].data[k]);
  });
  out << "\nPOLYGONS " << n << " " << 4 * n << "\n";
  writeRecords(out, n, 16, threads, [&](std::size_t t, char* p) {
    p = putBig<std::int32_t>(p, 3);
    for (const auto v : m.face(mesh, t))
      p = putBig<std::int32_t>(p, static_cast<std::int32_t>(v));
  });
  out << "\nCELL_DATA " << n << "\nCOLOR_SCALARS colors 3\n";
  writeRecords(out, n, 3, threads, [&](std::size_t t, char* p) {
    for (const auto c : faceColor(mesh, colors, t))
      p = putBig(p, c);
  });
  out << "\nSCALARS label unsigned_int 1\nLOOKUP_TABLE default\n";
  writeRecords(out, n, 4, threads, [&](std::size_t t, char* p) {
    putBig<std::uint32_t>(p, mesh.labels[t]);
  });
  out << "\nSCALARS class unsigned_char 1\nLOOKUP_TABLE default\n";
  writeRecords(out, n, 1, threads, [&](std::size_t t, char* p) {
    putBig<std::uint8_t>(p, static_cast<std::uint8_t>(mesh.classes[t]));
  });
  out << "\n";
  out.close();
  return static_cast<bool>(out);
}

LeafPoint
leafPoint(const pcl::selective_seg::OctreeLeaf& leaf)
{
  LeafPoint point;
  point.getVector3fMap() = leaf.centre;
  point.size = leaf.size;
  point.depth = leaf.depth;
  point.label = leaf.label;
  point.normal_x = leaf.normal.x();
  point.normal_y = leaf.normal.y();
  point.normal_z = leaf.normal.z();
  point.sigma_theta = leaf.sigma_theta;
  point.sigma_phi = leaf.sigma_phi;
  point.num_points = leaf.num_points;
  return point;
}

bool
writeLeaves(const std::string& path,
            const std::vector<pcl::selective_seg::OctreeLeaf>& leaves,
            int threads)
{
  const std::size_t n = leaves.size();
  if (n == 0 || n > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    return false;
  // The bytes of pcl::io::savePCDFileBinary() for a cloud of LeafPoint: PCL's header
  // for n points in one row (a cloud of that shape, without points), then each point's
  // fields in their order, padding left out. Written a block at a time instead of
  // through a map of the whole file, whose pages would count in the resident memory.
  struct FieldBytes {
    std::size_t offset, size;
  };
  std::vector<FieldBytes> fields;
  std::size_t record = 0;
  for (const auto& field : pcl::getFields<LeafPoint>())
    if (field.name != "_") {
      fields.push_back({field.offset, field.count * pcl::getFieldSize(field.datatype)});
      record += fields.back().size;
    }
  std::ofstream out(path, std::ios::binary);
  out << pcl::PCDWriter::generateHeader(pcl::PointCloud<LeafPoint>(),
                                        static_cast<int>(n))
      << "DATA binary\n";
  writeRecords(out, n, record, threads, [&](std::size_t l, char* p) {
    const LeafPoint point = leafPoint(leaves[l]);
    for (const auto& field : fields) {
      std::memcpy(p, reinterpret_cast<const char*>(&point) + field.offset, field.size);
      p += field.size;
    }
  });
  out.close();
  return static_cast<bool>(out);
}

bool
writeSummaryJson(const std::string& path,
                 const RunInfo& info,
                 const pcl::selective_seg::SegmentationResult& r,
                 int threads)
{
  const auto& p = info.parameters;
  const auto& c = r.counts;
  const auto& t = r.timings;
  const double deg = 180.0 / M_PI;
  std::ofstream out(path);
  out << std::setprecision(9) << "{\n  \"input\": " << jsonString(info.input)
      << ",\n  \"points\": " << info.num_points << ",\n  \"parameters\": {"
      << "\"split_deg\": " << p.max_normal_std_dev * deg
      << ", \"merge_deg\": " << p.max_merge_angle * deg
      << ", \"edge_deg\": " << p.max_edge_triangle_angle * deg
      << ", \"incidence_deg\": " << p.max_view_incidence_angle * deg
      << ", \"spread_frame\": " << jsonString(choiceName(p.normal_spread_frame))
      << ", \"segment_weight\": " << jsonString(choiceName(p.segment_normal_weight))
      << ", \"merge_with\": " << jsonString(choiceName(p.merge_with))
      << ", \"normal_rings\": " << p.normal_rings
      << ", \"normal_triangles\": " << jsonString(choiceName(p.point_normal_triangles))
      << ", \"edge_normal\": " << jsonString(choiceName(p.edge_triangle_normal))
      << ", \"min_voxel_m\": " << r.min_voxel_size
      << ", \"voxel_factor\": " << p.min_voxel_size_factor
      << ", \"min_split_points\": " << p.min_points_to_split
      << ", \"max_depth\": " << p.max_octree_depth
      << ", \"angle_step_rad\": " << p.angle_quantization
      << ", \"projection\": " << jsonString(choiceName(p.projection))
      << ", \"backend\": " << jsonString(info.backend) << "},\n  \"counts\": {"
      << "\"labeled\": " << c.labeled << ", \"shared_vertex\": " << c.shared_vertex
      << ", \"non_finite\": " << c.non_finite
      << ", \"behind_sensor\": " << c.behind_sensor
      << ", \"outside_indices\": " << c.outside_indices
      << ", \"without_normal\": " << c.without_normal
      << ", \"vertices\": " << r.num_vertices
      << ", \"triangles\": " << r.mesh.triangles.size()
      << ", \"leaves\": " << r.leaves.size() << ", \"segments\": " << r.segments.size()
      << (p.projection == pcl::selective_seg::ViewProjection::Panoramic
              ? (info.seam_closed ? ", \"seam_closed\": true"
                                  : ", \"seam_closed\": false")
              : "")
      << "},\n  \"median_spacing_m\": " << r.median_spacing
      << ",\n  \"timings_s\": {\"delaunay\": " << t.delaunay
      << ", \"normals\": " << t.normals << ", \"octree\": " << t.octree
      << ", \"merge\": " << t.merge << ", \"total\": " << t.total
      << "},\n  \"segments\": [";
  // One line per segment, formatted in blocks on the threads (%.9g is what the stream
  // prints at precision 9), a block per thread at a time, written in order.
  const std::size_t num_segments = r.segments.size();
  constexpr std::size_t kPerBlock = 4096;
  std::vector<std::string> blocks(static_cast<std::size_t>(std::max(1, threads)));
  inOrderBatches(
      (num_segments + kPerBlock - 1) / kPerBlock,
      threads,
      [&](std::size_t block, std::size_t k) {
        std::string& text = blocks[k];
        text.clear();
        const std::size_t first = block * kPerBlock;
        for (std::size_t s = first; s < std::min(num_segments, first + kPerBlock);
             ++s) {
          const auto& seg = r.segments[s];
          char line[320];
          const int length = std::snprintf(
              line,
              sizeof(line),
              "%s{\"label\": %u, \"points\": %zu, \"leaves\": %zu, \"area_m2\": %.9g, "
              "\"normal\": [%.9g, %.9g, %.9g]}",
              s ? ",\n    " : "\n    ",
              static_cast<unsigned>(seg.label),
              seg.num_points,
              seg.num_leaves,
              seg.area,
              static_cast<double>(seg.normal.x()),
              static_cast<double>(seg.normal.y()),
              static_cast<double>(seg.normal.z()));
          text.append(line, static_cast<std::size_t>(std::max(0, length)));
        }
      },
      [&](std::size_t k) { return static_cast<bool>(out << blocks[k]); });
  out << "\n  ]\n}\n";
  out.close();
  return static_cast<bool>(out);
}

} // namespace selseg_apps
