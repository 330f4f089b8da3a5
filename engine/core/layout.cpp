#include "engine/core/layout.hpp"

namespace mpx {

std::string_view blockName(Block block) {
  switch (block) {
    case Block::Position:
      return "position";
    case Block::Velocity:
      return "velocity";
    case Block::Thermal:
      return "thermal";
    case Block::Internal:
      return "internal";
    case Block::Multiplier:
      return "multiplier";
  }
  return "?";
}

Layout::Layout(const std::array<int, kBlockCount>& sizes) : sizes_(sizes) {
  for (int b = 0; b < kBlockCount; ++b) {
    offsets_[b] = total_;
    total_ += sizes_[b];
  }
}

Block Layout::blockOf(int dof) const {
  for (int b = kBlockCount - 1; b >= 0; --b)
    if (sizes_[b] > 0 && dof >= offsets_[b]) return static_cast<Block>(b);
  return Block::Position;
}

}  // namespace mpx
