// segment_run_cache.cpp: see segment_run_cache.h.
#include "vislib/kernel/segment_run_cache.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <cstring>

namespace vislib {

SegmentRunCache::Key SegmentRunCache::key_of(Vec3 from, Vec3 to) {
  const double v[6] = {from.x, from.y, from.z, to.x, to.y, to.z};
  Key k;
  std::memcpy(k.data(), v, sizeof v);
  return k;
}

void SegmentRunCache::plan_chains(const std::vector<std::pair<Vec3, Vec3>>& segments,
                                  int max_parts) {
  chains_.clear();
  chain_of_.clear();
  planned_ = 0;
  if (max_parts < 2) return;
  max_parts = std::min<int>(max_parts, int(kMaxSplitParts));
  // Group the axis-parallel segments by line: (axis, the bits of the two other coordinates).
  struct Item {
    double a, b;  // along the axis
    Vec3 from, to;
  };
  std::map<std::array<uint64_t, 3>, std::vector<Item>> lines;
  for (const auto& [from, to] : segments) {
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
    lines[line].push_back({from[axis], to[axis], from, to});
  }
  for (auto& [line, items] : lines) {
    std::sort(items.begin(), items.end(),
              [](const Item& p, const Item& q) { return p.a < q.a || (p.a == q.a && p.b < q.b); });
    items.erase(std::unique(items.begin(), items.end(),
                            [](const Item& p, const Item& q) { return p.a == q.a && p.b == q.b; }),
                items.end());
    // Maximal runs meeting end to end, cut into chains of at most max_parts from the low end.
    size_t i = 0;
    while (i < items.size()) {
      size_t j = i + 1;
      while (j < items.size() && j - i < size_t(max_parts) && items[j].a == items[j - 1].b) ++j;
      if (j - i >= 2) {
        Chain c;
        c.from = items[i].from;
        c.to = items[j - 1].to;
        const double a = items[i].a, len = items[j - 1].b - a;
        bool ok = true;
        for (size_t m = i + 1; m < j; ++m) {
          double s = (items[m].a - a) / len;
          ok = ok && s > 0 && s < 1 && (c.splits.empty() || c.splits.back() < s);
          c.splits.push_back(s);
        }
        if (ok) {
          c.remaining.assign(j - i, 0);
          for (size_t m = i; m < j; ++m)
            chain_of_[key_of(items[m].from, items[m].to)] = {uint32_t(chains_.size()),
                                                             uint32_t(m - i)};
          chains_.push_back(std::move(c));
          ++planned_;
        }
      }
      i = j;
    }
  }
}

void SegmentRunCache::expect(Vec3 from, Vec3 to) {
  std::lock_guard<std::mutex> lock(mutex_);
  const Key key = key_of(from, to);
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

std::shared_ptr<SegmentRunCache::Parts> SegmentRunCache::run_chain(const Chain& c,
                                                                   const RunFn& compute) {
  auto parts = std::make_shared<Parts>();
  tbb::this_task_arena::isolate([&] {
    SegmentResult whole = compute(c.from, c.to, c.splits);
    if (c.splits.empty()) {
      parts->push_back(std::make_shared<const SegmentResult>(std::move(whole)));
      return;
    }
    for (size_t i = 0; i < whole.visible_parts.size(); ++i) {
      auto part = std::make_shared<SegmentResult>();
      part->visible = std::move(whole.visible_parts[i]);
      part->stats = whole.stats;  // the chain's run, shown on every part
      parts->push_back(std::move(part));
    }
  });
  computed_.fetch_add(1);
  return parts;
}

std::shared_ptr<const SegmentResult> SegmentRunCache::get(Vec3 from, Vec3 to, const RunFn& compute,
                                                          bool* computed) {
  if (computed) *computed = true;
  std::unique_lock<std::mutex> lock(mutex_);
  auto ref = chain_of_.find(key_of(from, to));
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
  const bool first = !c.started;
  std::promise<std::shared_ptr<Parts>> promise;
  if (first) {
    c.started = true;
    c.result = promise.get_future().share();
  }
  auto future = c.result;
  lock.unlock();
  if (computed) *computed = first;
  if (first) {
    try {
      promise.set_value(run_chain(c, compute));
    } catch (...) {
      promise.set_exception(std::current_exception());
    }
  } else {
    shared_.fetch_add(1);
  }
  std::shared_ptr<Parts> parts;
  try {
    parts = future.get();
  } catch (...) {
    lock.lock();
    if (c.remaining[part] > 0) --c.remaining[part];
    throw;
  }
  lock.lock();
  std::shared_ptr<const SegmentResult> mine = (*parts)[part];
  if (c.remaining[part] > 0 && --c.remaining[part] == 0)
    (*parts)[part].reset();  // its last use: release it
  bool done = true;
  for (uint32_t r : c.remaining) done = done && r == 0;
  if (done) c.result = {};
  if (!mine) {
    // Released by a concurrent use beyond those announced: run it again for this one.
    lock.unlock();
    if (computed) *computed = true;
    return (*run_chain(c, compute))[part];
  }
  return mine;
}

}  // namespace vislib
