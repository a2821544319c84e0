// Greedy set cover of a share of a universe, for the known-map oracle (oracle_strategy.hpp):
// the sets are (viewpoint, yaw) pairs, the elements the voxels of T each one sees.
//
// Sets come in groups of at most 32 members that one evaluation lists together: a viewpoint's
// ray cast gives every yaw's voxels at once, as (voxel, mask of the yaws that see it). The greedy
// picks, while less than `fraction` of the observable elements (those some set holds) is covered,
// the set that covers the most uncovered ones. It is lazy (Minoux's accelerated greedy): a set's
// gain only shrinks as more is covered, so a gain computed in an earlier round is an upper bound,
// and a group is evaluated again only when one of its bounds comes first; the picks are those of
// the plain greedy (ties aside). Then a pick is dropped, last picked first, when the others still
// cover the required share without it: the greedy's early picks can be made redundant by later
// ones.
#pragma once

#include <cstdint>
#include <vector>

namespace semx::planner {

struct MaskedElement {
  int32_t element = 0;  // in [0, num_elements)
  uint32_t members = 0;  // bit m: member m of the group holds it
};

class CoverSource {
 public:
  virtual ~CoverSource() = default;
  virtual int groups() const = 0;
  // Members per group (<= 32), the same for every group.
  virtual int members() const = 0;
  // The group's elements, each once, with the members holding it (replaces `out`).
  virtual void elements(int group, std::vector<MaskedElement>& out) = 0;
};

struct CoverPick {
  int group = 0;
  int member = 0;
  int64_t gain = 0;  // uncovered elements it covered when picked
};

struct CoverResult {
  std::vector<CoverPick> picks;  // in the order picked (the dropped ones removed)
  int64_t observable = 0;        // elements some set holds
  int64_t required = 0;          // ceil(fraction * observable)
  int64_t covered = 0;           // by the picks
  int64_t evaluations = 0;       // calls of CoverSource::elements
  int64_t dropped = 0;           // picks found redundant afterwards
};

// `covered` (optional, num_elements flags): elements already covered before the first pick (the
// oracle's first pass saw them); they count toward the share and no pick is chosen for them.
CoverResult greedy_cover(CoverSource& source, int32_t num_elements, double fraction,
                         const std::vector<uint8_t>* covered = nullptr);

// A CoverSource over sets given in full (tests, small problems): sets[g][m] lists group g's
// member m's elements.
class ListCoverSource : public CoverSource {
 public:
  explicit ListCoverSource(std::vector<std::vector<std::vector<int32_t>>> sets);
  int groups() const override { return static_cast<int>(sets_.size()); }
  int members() const override { return members_; }
  void elements(int group, std::vector<MaskedElement>& out) override;

 private:
  std::vector<std::vector<std::vector<int32_t>>> sets_;
  int members_ = 1;
};

}  // namespace semx::planner
