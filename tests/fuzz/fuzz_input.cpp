#include "fuzz_input.hpp"

#include <unistd.h>

#include <fstream>
#include <stdexcept>

namespace sg::fuzz {

namespace {

std::filesystem::path scratch_dir() {
  static const std::filesystem::path dir = [] {
    std::error_code ec;
    return std::filesystem::is_directory("/dev/shm", ec) ? std::filesystem::path("/dev/shm")
                                                         : std::filesystem::temp_directory_path();
  }();
  return dir;
}

void write_file(const std::filesystem::path& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) throw std::runtime_error("fuzz: cannot write " + path.string());
}

}  // namespace

std::filesystem::path write_input(const std::uint8_t* data, std::size_t size,
                                  const std::string& suffix) {
  // One file per process and suffix, so parallel fuzz jobs (-jobs=N) do not share files; in
  // memory (/dev/shm) when there is one, since every execution writes it.
  const std::filesystem::path path =
      scratch_dir() / ("sg_fuzz_" + std::to_string(::getpid()) + suffix);
  write_file(path, data, size);
  return path;
}

std::filesystem::path write_named_input(const std::uint8_t* data, std::size_t size,
                                        const std::filesystem::path& name) {
  const std::filesystem::path path =
      scratch_dir() / ("sg_fuzz_" + std::to_string(::getpid()) + ".d") / name;
  std::filesystem::create_directories(path.parent_path());
  write_file(path, data, size);
  return path;
}

}  // namespace sg::fuzz
