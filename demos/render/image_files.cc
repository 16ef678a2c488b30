#include "demos/render/image_files.h"

#include <stb_image_write.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace taut::render {

void WritePng(const Image& image, const std::string& path) {
  TAUT_DEMAND(image.width > 0 && image.height > 0, "PNG ", path, ": empty image");
  const int ok =
      stbi_write_png(path.c_str(), image.width, image.height, 3, image.rgb.data(), image.width * 3);
  TAUT_DEMAND(ok != 0, "cannot write PNG ", path);
}

GifWriter::GifWriter(std::string path, int delay_cs)
    : path_(std::move(path)), delay_cs_(delay_cs) {}

GifWriter::~GifWriter() { RemoveFrames(); }

void GifWriter::RemoveFrames() {
  std::error_code ignored;
  for (const std::string& frame : frames_) std::filesystem::remove(frame, ignored);
  frames_.clear();
}

void GifWriter::AddFrame(const Image& frame) {
  if (frames_.empty()) {
    width_ = frame.width;
    height_ = frame.height;
  }
  TAUT_DEMAND(frame.width == width_ && frame.height == height_, "GIF ", path_,
              ": frames differ in size");
  char suffix[32];
  std::snprintf(suffix, sizeof(suffix), ".frame%05d.rgb", static_cast<int>(frames_.size()));
  const std::string name = path_ + suffix;
  std::ofstream out(name, std::ios::binary);
  out.write(reinterpret_cast<const char*>(frame.rgb.data()),
            static_cast<std::streamsize>(frame.rgb.size()));
  TAUT_DEMAND(out.good(), "cannot write GIF frame ", name);
  frames_.push_back(name);
}

void GifWriter::Finish() {
  if (frames_.empty()) return;
  // The paths go into gnuplot's script and a shell command between single quotes.
  TAUT_DEMAND(path_.find('\'') == std::string::npos, "GIF ", path_, ": no ' in the path, please");
  const std::string script_path = path_ + ".gp";
  {
    std::ofstream gp(script_path);
    // Plot each raw frame pixel for pixel over the whole canvas (no border, tics or margins).
    gp << "set terminal gif animate delay " << delay_cs_ << " loop 0 optimize size " << width_
       << "," << height_ << "\n"
       << "set output '" << path_ << "'\n"
       << "unset border; unset tics; unset key; unset colorbox\n"
       << "set lmargin at screen 0; set rmargin at screen 1\n"
       << "set tmargin at screen 1; set bmargin at screen 0\n"
       << "set xrange [-0.5:" << width_ - 0.5 << "]; set yrange [-0.5:" << height_ - 0.5 << "]\n";
    for (const std::string& frame : frames_)
      gp << "plot '" << frame << "' binary array=(" << width_ << "," << height_
         << ") flipy format='%uchar%uchar%uchar' with rgbimage\n";
    gp << "unset output\n";
  }
  const std::string command = "gnuplot '" + script_path + "' 2>'" + path_ + ".log'";
  const int status = std::system(command.c_str());
  std::error_code ignored;
  std::filesystem::remove(script_path, ignored);
  RemoveFrames();
  TAUT_DEMAND(status == 0, "gnuplot failed to write ", path_, " (see ", path_,
              ".log; install gnuplot-nox)");
  std::filesystem::remove(path_ + ".log", ignored);
}

}  // namespace taut::render
