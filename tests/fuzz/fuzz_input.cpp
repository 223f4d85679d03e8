#include "fuzz_input.hpp"

#include <unistd.h>

#include <fstream>
#include <stdexcept>

namespace sg::fuzz {

std::filesystem::path write_input(const std::uint8_t* data, std::size_t size,
                                  const std::string& suffix) {
  // One file per process and suffix, so parallel fuzz jobs (-jobs=N) do not share files; in
  // memory (/dev/shm) when there is one, since every execution writes it.
  static const std::filesystem::path dir = [] {
    std::error_code ec;
    return std::filesystem::is_directory("/dev/shm", ec) ? std::filesystem::path("/dev/shm")
                                                         : std::filesystem::temp_directory_path();
  }();
  const std::filesystem::path path = dir / ("sg_fuzz_" + std::to_string(::getpid()) + suffix);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) throw std::runtime_error("fuzz: cannot write " + path.string());
  return path;
}

}  // namespace sg::fuzz
