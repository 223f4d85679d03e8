#include "sg/par/memory.hpp"

#include <cstdlib>
#include <vector>

namespace sg::par {

std::size_t prefault_heap(std::size_t bytes, std::size_t block_bytes) {
  constexpr std::size_t kPage = 4096;
  if (block_bytes < kPage) block_bytes = kPage;
  std::vector<volatile char*> blocks;
  std::size_t touched = 0;
  while (touched < bytes) {
    auto* block = static_cast<volatile char*>(std::malloc(block_bytes));
    if (!block) break;  // not worth failing over: the pipeline just faults its pages in later
    for (std::size_t i = 0; i < block_bytes; i += kPage) block[i] = 0;
    blocks.push_back(block);
    touched += block_bytes;
  }
  for (volatile char* block : blocks) std::free(const_cast<char*>(block));
  return touched;
}

}  // namespace sg::par
