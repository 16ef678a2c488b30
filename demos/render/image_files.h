// Writing pictures: PNG through stb_image_write, animated GIF through gnuplot's gif terminal.
#pragma once

#include <string>
#include <vector>

#include "demos/render/image.h"

namespace taut::render {

// Writes image as an 8-bit RGB PNG; throws InputError when the file cannot be written.
void WritePng(const Image& image, const std::string& path);

// Collects equally sized frames on disk (raw RGB next to the GIF) and, in Finish(), turns them
// into an animated GIF with one gnuplot run (`set terminal gif animate`, libgd's encoder), then
// removes the raw frames.
class GifWriter {
 public:
  // delay: hundredths of a second per frame.
  GifWriter(std::string path, int delay_cs);
  ~GifWriter();
  void AddFrame(const Image& frame);
  // Writes the GIF; throws InputError when gnuplot is missing or fails. No-op without frames.
  void Finish();
  int num_frames() const { return static_cast<int>(frames_.size()); }

 private:
  void RemoveFrames();
  std::string path_;
  int delay_cs_;
  int width_ = 0, height_ = 0;
  std::vector<std::string> frames_;
};

}  // namespace taut::render
