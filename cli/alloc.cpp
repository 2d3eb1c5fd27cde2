// alloc.cpp: the `pvs` executable's replacement of the global operator new. Identical to the
// default (malloc, the new-handler loop, std::bad_alloc) except that a failed request records its
// size (vislib::record_failed_allocation), so that "out of memory" messages say how much was asked
// for (vislib::OutOfMemory, error.h). Replacing operator new is standard C++
// ([replacement.functions]); the sized, array and nothrow forms forward here, the aligned forms
// keep the library default.
#include <cstdlib>
#include <new>

#include "vislib/base/error.h"

// Under AddressSanitizer the sanitizer's own operator new stays (it checks new/delete pairing).
#if !defined(__SANITIZE_ADDRESS__)

void* operator new(std::size_t size) {
  if (size == 0) size = 1;
  while (true) {
    if (void* p = std::malloc(size)) return p;
    std::new_handler handler = std::get_new_handler();
    if (!handler) {
      vislib::record_failed_allocation(size);
      throw std::bad_alloc();
    }
    handler();
  }
}

void* operator new[](std::size_t size) {
  return ::operator new(size);
}

void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return ::operator new(size);
  } catch (...) {
    return nullptr;
  }
}

void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return ::operator new(size);
  } catch (...) {
    return nullptr;
  }
}

void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}

#endif  // !__SANITIZE_ADDRESS__
