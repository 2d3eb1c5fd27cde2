// segment_run_cache.cpp: see segment_run_cache.h.
#include "vislib/kernel/segment_run_cache.h"

#include <tbb/task_arena.h>

#include <cstring>

namespace vislib {

SegmentRunCache::Key SegmentRunCache::key_of(Vec3 from, Vec3 to) {
  const double v[6] = {from.x, from.y, from.z, to.x, to.y, to.z};
  Key k;
  std::memcpy(k.data(), v, sizeof v);
  return k;
}

void SegmentRunCache::expect(Vec3 from, Vec3 to) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++entries_[key_of(from, to)].remaining;
}

size_t SegmentRunCache::entries_held() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return entries_.size();
}

std::shared_ptr<const SegmentResult> SegmentRunCache::get(
    Vec3 from, Vec3 to, const std::function<SegmentResult()>& compute, bool* computed) {
  auto run = [&] {
    std::shared_ptr<const SegmentResult> r;
    tbb::this_task_arena::isolate([&] { r = std::make_shared<const SegmentResult>(compute()); });
    computed_.fetch_add(1);
    return r;
  };
  const Key key = key_of(from, to);
  std::unique_lock<std::mutex> lock(mutex_);
  auto it = entries_.find(key);
  if (it == entries_.end() || (it->second.remaining <= 1 && !it->second.started)) {
    // Used once (or never announced): nothing to share.
    if (it != entries_.end()) entries_.erase(it);
    lock.unlock();
    if (computed) *computed = true;
    return run();
  }
  Entry& e = it->second;
  const bool first = !e.started;
  std::promise<std::shared_ptr<const SegmentResult>> promise;
  if (first) {
    e.started = true;
    e.result = promise.get_future().share();
  }
  auto future = e.result;
  if (e.remaining > 0) --e.remaining;
  if (e.remaining == 0) entries_.erase(it);  // the future copy keeps the result alive
  lock.unlock();
  if (computed) *computed = first;
  if (first) {
    try {
      promise.set_value(run());
    } catch (...) {
      promise.set_exception(std::current_exception());
    }
  } else {
    shared_.fetch_add(1);
  }
  return future.get();
}

}  // namespace vislib
