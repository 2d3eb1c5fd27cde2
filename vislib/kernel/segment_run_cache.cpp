// segment_run_cache.cpp: see segment_run_cache.h.
#include "vislib/kernel/segment_run_cache.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstring>

namespace vislib {

SegmentRunCache::Key SegmentRunCache::key_of(Vec3 from, Vec3 to, Vec3 side_normal) {
  const double v[9] = {from.x, from.y,        from.z,        to.x,         to.y,
                       to.z,   side_normal.x, side_normal.y, side_normal.z};
  Key k;
  std::memcpy(k.data(), v, sizeof v);
  return k;
}

std::vector<std::vector<SegmentEnds>> segments_end_to_end(
    const std::vector<SegmentEnds>& segments) {
  // Group the axis-parallel segments by line: (axis, the bits of the two other coordinates).
  struct Item {
    double a, b;  // along the axis
    SegmentEnds s;
  };
  std::map<std::array<uint64_t, 3>, std::vector<Item>> lines;
  for (const SegmentEnds& s : segments) {
    const auto& [from, to] = s;
    int axis = -1, differing = 0;
    for (int i = 0; i < 3; ++i)
      if (from[i] != to[i]) {
        axis = i;
        ++differing;
      }
    if (differing != 1 || !(from[axis] < to[axis])) continue;
    std::array<uint64_t, 3> line{uint64_t(axis), 0, 0};
    int k = 1;
    for (int i = 0; i < 3; ++i)
      if (i != axis) {
        const double v = from[i];
        std::memcpy(&line[size_t(k++)], &v, sizeof v);
      }
    lines[line].push_back({from[axis], to[axis], s});
  }
  std::vector<std::vector<SegmentEnds>> out;
  for (auto& [line, items] : lines) {
    std::sort(items.begin(), items.end(),
              [](const Item& p, const Item& q) { return p.a < q.a || (p.a == q.a && p.b < q.b); });
    items.erase(std::unique(items.begin(), items.end(),
                            [](const Item& p, const Item& q) { return p.a == q.a && p.b == q.b; }),
                items.end());
    for (size_t i = 0, j; i < items.size(); i = j) {  // maximal stretches meeting end to end
      j = i + 1;
      while (j < items.size() && items[j].a == items[j - 1].b) ++j;
      if (j - i < 2) continue;
      out.emplace_back();
      for (size_t m = i; m < j; ++m) out.back().push_back(items[m].s);
    }
  }
  return out;
}

std::vector<double> chain_splits(const std::vector<SegmentEnds>& stretch, size_t i, size_t j) {
  const Vec3 from = stretch[i].first, to = stretch[j - 1].second;
  const int axis = from.x != to.x ? 0 : from.y != to.y ? 1 : 2;
  const double a = from[axis], len = to[axis] - a;
  std::vector<double> splits;
  for (size_t m = i + 1; m < j; ++m) splits.push_back((stretch[m].first[axis] - a) / len);
  return splits;
}

void SegmentRunCache::plan_chains(const std::vector<SegmentEnds>& segments, int max_parts) {
  chains_.clear();
  chain_of_.clear();
  planned_ = 0;
  if (max_parts < 2) return;
  max_parts = std::min<int>(max_parts, int(kMaxSplitParts));
  for (const std::vector<SegmentEnds>& stretch : segments_end_to_end(segments)) {
    // Cut into chains of at most max_parts from the low end.
    for (size_t i = 0, j; i < stretch.size(); i = j) {
      j = std::min(stretch.size(), i + size_t(max_parts));
      if (j - i < 2) continue;
      Chain c;
      c.from = stretch[i].first;
      c.to = stretch[j - 1].second;
      c.splits = chain_splits(stretch, i, j);
      bool ok = true;
      for (size_t m = 0; m < c.splits.size(); ++m)
        ok = ok && c.splits[m] > 0 && c.splits[m] < 1 && (m == 0 || c.splits[m - 1] < c.splits[m]);
      if (!ok) continue;
      c.remaining.assign(j - i, 0);
      for (size_t m = i; m < j; ++m)
        chain_of_[key_of(stretch[m].first, stretch[m].second)] = {uint32_t(chains_.size()),
                                                                  uint32_t(m - i)};
      chains_.push_back(std::move(c));
      ++planned_;
    }
  }
}

void SegmentRunCache::expect(Vec3 from, Vec3 to, Vec3 side_normal) {
  std::lock_guard<std::mutex> lock(mutex_);
  const Key key = key_of(from, to, side_normal);
  auto ref = chain_of_.find(key);
  if (ref == chain_of_.end()) {
    // A segment in no planned chain: a run of one part.
    Chain c;
    c.from = from;
    c.to = to;
    c.remaining.assign(1, 0);
    ref = chain_of_.emplace(key, ChainRef{uint32_t(chains_.size()), 0}).first;
    chains_.push_back(std::move(c));
  }
  ++chains_[ref->second.chain].remaining[ref->second.part];
}

size_t SegmentRunCache::entries_held() const {
  std::lock_guard<std::mutex> lock(mutex_);
  size_t held = 0;
  for (const Chain& c : chains_)
    for (uint32_t r : c.remaining) held += r > 0 ? 1 : 0;
  return held;
}

std::shared_ptr<SegmentRunCache::Parts> SegmentRunCache::split_parts(SegmentResult whole,
                                                                     bool split) {
  auto parts = std::make_shared<Parts>();
  if (!split) {
    parts->push_back(std::make_shared<const SegmentResult>(std::move(whole)));
    return parts;
  }
  for (size_t i = 0; i < whole.visible_parts.size(); ++i) {
    auto part = std::make_shared<SegmentResult>();
    part->visible = std::move(whole.visible_parts[i]);
    part->stats = whole.stats;  // the chain's run, shown on every part
    parts->push_back(std::move(part));
  }
  return parts;
}

std::shared_ptr<SegmentRunCache::Parts> SegmentRunCache::run_chain(const Chain& c,
                                                                   const RunFn& compute,
                                                                   bool isolated) {
  std::shared_ptr<Parts> parts;
  auto run = [&] { parts = split_parts(compute(c.from, c.to, c.splits), !c.splits.empty()); };
  // Isolated, the computing thread never picks up a task that would wait for an entry it holds.
  // Inside collaborative_call_once the call is isolated already, with a tag its waiting callers
  // share: a nested isolate would keep them from the run's tiles.
  if (isolated)
    tbb::this_task_arena::isolate(run);
  else
    run();
  computed_.fetch_add(1);
  return parts;
}

void SegmentRunCache::provide(Vec3 from, Vec3 to, const std::vector<double>& splits,
                              SegmentResult whole) {
  std::lock_guard<std::mutex> lock(mutex_);
  const Key key = key_of(from, to);
  for (Chain& c : chains_) {
    if (key_of(c.from, c.to) != key || c.splits != splits) continue;
    bool expected = false;
    for (uint32_t r : c.remaining) expected = expected || r > 0;
    const size_t parts = c.splits.empty() ? 0 : c.splits.size() + 1;  // visible_parts of its run
    if (c.started || !expected || whole.visible_parts.size() != parts) return;
    tbb::collaborative_call_once(
        *c.once, [&] { c.parts = split_parts(std::move(whole), !c.splits.empty()); });
    c.started = true;
    c.provided = true;
    computed_.fetch_add(1);
    return;
  }
}

void SegmentRunCache::expect_family(const Key& family) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++family_users_[family];
}

uint32_t SegmentRunCache::family_users(const Key& family) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = family_users_.find(family);
  return it == family_users_.end() ? 0 : it->second;
}

std::shared_ptr<const SegmentResult> SegmentRunCache::get(Vec3 from, Vec3 to, const RunFn& compute,
                                                          bool* computed, Vec3 side_normal,
                                                          uint32_t users) {
  if (computed) *computed = true;
  std::unique_lock<std::mutex> lock(mutex_);
  const Key key = key_of(from, to, side_normal);
  auto ref = chain_of_.find(key);
  if (ref == chain_of_.end() && users > 1) {
    // The first use of a family's run: announced now for all of its users.
    Chain c;
    c.from = from;
    c.to = to;
    c.remaining.assign(1, users);
    ref = chain_of_.emplace(key, ChainRef{uint32_t(chains_.size()), 0}).first;
    chains_.push_back(std::move(c));
  }
  if (ref == chain_of_.end()) {
    // Never announced: nothing to share.
    lock.unlock();
    Chain alone;
    alone.from = from;
    alone.to = to;
    return (*run_chain(alone, compute))[0];
  }
  Chain& c = chains_[ref->second.chain];
  const uint32_t part = ref->second.part;
  if (c.remaining[part] == 0) {
    // A use beyond those announced: run it again for this one.
    lock.unlock();
    return (*run_chain(c, compute))[part];
  }
  const bool claims = c.provided;  // the first use of a provided run counts as computing it
  c.provided = false;
  c.started = true;
  lock.unlock();
  // The first caller computes; callers that arrive meanwhile work on the same run's tiles (the
  // kernel is TBB-parallel inside) and see its parts, or its error, once it is done.
  bool ran = false;
  const auto t0 = std::chrono::steady_clock::now();
  tbb::collaborative_call_once(*c.once, [&] {
    ran = true;
    try {
      c.parts = run_chain(c, compute, /*isolated=*/false);
    } catch (...) {
      c.error = std::current_exception();
    }
  });
  if (computed) *computed = ran || claims;
  if (!ran && !claims) {
    shared_.fetch_add(1);
    wait_ns_.fetch_add(uint64_t(
        std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0)
            .count()));
  }
  lock.lock();
  const bool last = c.remaining[part] > 0 && --c.remaining[part] == 0;
  if (c.error) std::rethrow_exception(c.error);
  std::shared_ptr<const SegmentResult> mine = (*c.parts)[part];
  if (last) (*c.parts)[part].reset();  // its last use: release it
  bool done = true;
  for (uint32_t r : c.remaining) done = done && r == 0;
  if (done) c.parts.reset();
  if (!mine) {
    // Released by a concurrent use beyond those announced: run it again for this one.
    lock.unlock();
    if (computed) *computed = true;
    return (*run_chain(c, compute))[part];
  }
  return mine;
}

}  // namespace vislib
