/*
 * SPDX-License-Identifier: BSD-3-Clause
 *
 *  pcl_selective_seg: segmentation of 3-D surface point clouds for selective sensing.
 */

// check_screenshot: does a picture of pcl_selective_seg_viewer show segments?
//
// Usage: check_screenshot FILE.png WIDTH HEIGHT MIN_HUES MIN_PIXELS
//
// Passes (exit 0) when the PNG has the given size, at least a quarter of its pixels are
// not background, and at least MIN_HUES of the 12 hue sectors (30 degrees each) hold
// MIN_PIXELS saturated pixels or more: segments are drawn in distinct hues. Prints the
// hue histogram either way; exit 1 on failure, 2 on bad arguments.

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace {

constexpr int kSectors = 12;

/** Pixel statistics of an RGB(A) picture. */
struct PixelCounts {
  std::array<long, kSectors> hue{}; ///< saturated pixels per 30-degree hue sector
  long foreground = 0;              ///< pixels brighter than the black background
  long total = 0;
};

/** Hue sector of a saturated, not dark pixel, or -1. */
int
hueSector(int r, int g, int b)
{
  const int hi = std::max({r, g, b}), lo = std::min({r, g, b});
  if (hi < 64 || hi - lo < hi / 2)
    return -1;
  double hue;
  if (hi == r)
    hue = 60.0 * (g - b) / (hi - lo);
  else if (hi == g)
    hue = 120.0 + 60.0 * (b - r) / (hi - lo);
  else
    hue = 240.0 + 60.0 * (r - g) / (hi - lo);
  if (hue < 0.0)
    hue += 360.0;
  return std::min(kSectors - 1, static_cast<int>(hue / (360.0 / kSectors)));
}

PixelCounts
countPixels(vtkImageData* image)
{
  PixelCounts counts;
  const int* dims = image->GetDimensions();
  const int channels = image->GetNumberOfScalarComponents();
  const auto* pixel = static_cast<const unsigned char*>(image->GetScalarPointer());
  counts.total = static_cast<long>(dims[0]) * dims[1];
  for (long i = 0; i < counts.total; ++i, pixel += channels) {
    if (pixel[0] + pixel[1] + pixel[2] > 48)
      ++counts.foreground;
    const int sector = hueSector(pixel[0], pixel[1], pixel[2]);
    if (sector >= 0)
      ++counts.hue[sector];
  }
  return counts;
}

} // namespace

int
main(int argc, char** argv)
{
  if (argc != 6) {
    std::fprintf(
        stderr, "Usage: %s FILE.png WIDTH HEIGHT MIN_HUES MIN_PIXELS\n", argv[0]);
    return 2;
  }
  const int width = std::atoi(argv[2]), height = std::atoi(argv[3]);
  const int min_hues = std::atoi(argv[4]);
  const long min_pixels = std::atol(argv[5]);
  vtkNew<vtkPNGReader> reader;
  if (!reader->CanReadFile(argv[1])) {
    std::fprintf(stderr, "FAIL: '%s' is missing or not a PNG\n", argv[1]);
    return 1;
  }
  reader->SetFileName(argv[1]);
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  const int* dims = image->GetDimensions();
  if (dims[0] != width || dims[1] != height ||
      image->GetNumberOfScalarComponents() < 3 ||
      image->GetScalarType() != VTK_UNSIGNED_CHAR) {
    std::fprintf(stderr,
                 "FAIL: '%s' is %dx%d with %d channels, expected %dx%d 8-bit RGB\n",
                 argv[1],
                 dims[0],
                 dims[1],
                 image->GetNumberOfScalarComponents(),
                 width,
                 height);
    return 1;
  }
  const PixelCounts counts = countPixels(image);
  int hues = 0;
  std::printf("saturated pixels per 30-degree hue sector:");
  for (const long n : counts.hue) {
    std::printf(" %ld", n);
    hues += n >= min_pixels;
  }
  std::printf("\nforeground: %ld of %ld pixels; hue sectors with >= %ld pixels: %d\n",
              counts.foreground,
              counts.total,
              min_pixels,
              hues);
  if (4 * counts.foreground < counts.total || hues < min_hues) {
    std::fprintf(
        stderr, "FAIL: expected >= 25%% foreground and >= %d hue sectors\n", min_hues);
    return 1;
  }
  std::printf("PASS\n");
  return 0;
}
