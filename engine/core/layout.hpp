#pragma once
// The state z is one flat vector of blocks. A block exists (has non-zero size) only when some
// component of the scene asks for it, so a scene pays only for the effects it declares.
#include <array>
#include <cassert>
#include <string_view>

namespace mpx {

enum class Block { Position, Velocity, Thermal, Internal, Multiplier };
inline constexpr int kBlockCount = 5;

std::string_view blockName(Block block);

class Layout {
 public:
  // Block sizes in order Position, Velocity, Thermal, Internal, Multiplier.
  explicit Layout(const std::array<int, kBlockCount>& sizes = {});

  int size(Block block) const { return sizes_[index(block)]; }
  int offset(Block block) const { return offsets_[index(block)]; }
  bool has(Block block) const { return size(block) > 0; }
  int total() const { return total_; }
  // Global index of entry `local` of a block.
  int dof(Block block, int local) const {
    assert(local >= 0 && local < size(block) && "a block-local index outside its block");
    return offset(block) + local;
  }
  Block blockOf(int dof) const;

 private:
  static int index(Block block) { return static_cast<int>(block); }
  std::array<int, kBlockCount> sizes_{};
  std::array<int, kBlockCount> offsets_{};
  int total_ = 0;
};

}  // namespace mpx
