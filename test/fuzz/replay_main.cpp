/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// A main() for the fuzz targets in builds without libFuzzer: runs the target once on
// every file of the folders (or files) given, so that the seed corpus and every crash
// the fuzzers ever found are regression tests of the normal build. Exit code 0 when
// every input ran, 1 when a folder is missing or empty (a test that cannot fail is no
// test); a crash or an abort ends the process, as under libFuzzer.

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);
extern "C" int LLVMFuzzerInitialize(int* argc, char*** argv);

int
main(int argc, char** argv)
{
  namespace fs = std::filesystem;
  LLVMFuzzerInitialize(&argc, &argv);
  std::size_t runs = 0;
  for (int a = 1; a < argc; ++a) {
    std::vector<fs::path> files;
    if (fs::is_directory(argv[a])) {
      for (const auto& e : fs::directory_iterator(argv[a]))
        if (e.is_regular_file())
          files.push_back(e.path());
    }
    else if (fs::is_regular_file(argv[a]))
      files.emplace_back(argv[a]);
    if (files.empty()) {
      std::fprintf(stderr, "replay: no input in '%s'\n", argv[a]);
      return 1;
    }
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      std::ifstream in(f, std::ios::binary);
      const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
      LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()),
                             bytes.size());
      ++runs;
    }
  }
  std::printf("replay: %zu inputs ran\n", runs);
  return runs > 0 ? 0 : 1;
}
