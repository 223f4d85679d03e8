#include "fuzz_input.hpp"

#include <unistd.h>

#include <fstream>
#include <stdexcept>

// ASan options of every fuzz target (ASAN_OPTIONS overrides them; reproduce a finding with
// ASAN_OPTIONS=malloc_context_size=30 for full allocation stacks).
// malloc_context_size=2: ASan keeps the stack of every allocation and free, unwinding by frame
// pointers, which yaml-cpp, OpenCV and libstdc++ (not built by us) do not keep. From the third
// frame on it reads whatever those libraries left in the frame-pointer register, so the stacks
// differ from one execution to the next and ASan's stack depot never stops growing: one
// calibration file run 1,000 and 4,000 times left 44,084 and 141,589 stacks (the default of 30
// frames; 3 or 4 frames grow as fast). fuzz_calibration's RSS went from 565 MB after 16k
// executions to 1,024 MB after 320k (1.5 KB per execution: about 2 GB, fuzz.sh's -rss_limit_mb,
// by 1M executions, which would end the run as a false out-of-memory), and it spent 11-23% of
// its time in StackDepot::Put. Two frames (the allocator and its caller) are exact and take a
// fixed set of stacks (714 for 100k runs of a calibration). This limits only the allocated-by and
// freed-by stacks of a report; the stack of the bad access itself is printed in full.
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
