#include "fuzz_input.hpp"

#include <unistd.h>

#include <fstream>
#include <stdexcept>

// ASan options of every fuzz target (ASAN_OPTIONS overrides them; reproduce a finding with
// ASAN_OPTIONS=malloc_context_size=30 for full allocation stacks).
// malloc_context_size=2: ASan keeps the stack of every allocation and free, unwinding by frame
// pointers, which yaml-cpp, OpenCV and libstdc++ (not built by us) do not keep. From the third
// frame on it reads whatever those libraries left in the frame-pointer register, so the stacks
// differ from one execution to the next and ASan's stack depot never stops growing: the same
// camera.yaml run 500 and 2000 times left 13,889 and 33,388 stacks (malloc_context_size=3, same
// with 30), fuzz_calibration grew by about 2 KB per execution (RSS 105 MB -> 1,030 MB in 316k
// executions, so a 1M run ends at -rss_limit_mb=2048 as a false out-of-memory) and spent 11-23%
// of its time in StackDepot::Put. Two frames (the allocator and its caller) are exact and take a
// fixed set of stacks (714 for 100k runs of a calibration). The report of a bad access keeps its
// full stack (ASan unwinds that one with the debug info).
extern "C" const char* __asan_default_options() { return "malloc_context_size=2"; }

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
