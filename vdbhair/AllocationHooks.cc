/// @file AllocationHooks.cc
/// @brief The replaceable global allocation functions ([new.delete]), counting against the
/// calling thread's AllocationBudget (Memory.h) when one is alive.
///
/// Linked as an object into every program and module that links the library (CMakeLists.txt);
/// they export them, so OpenVDB's allocations come here too.
#include <vdbhair/Memory.h>

#include <cstdlib>
#include <new>

#include <malloc.h>

#define VDBHAIR_HOOK __attribute__((visibility("default")))

// The replaceable global allocation functions ([new.delete]), counting against the calling
// thread's AllocationBudget when one is alive: every form but the aligned ones, which are left to
// the standard library (or a sanitizer's runtime) whole: they allocate and free on their own,
// outside any budget. A runtime's nothrow new must not pair with this delete.
VDBHAIR_HOOK void* operator new(std::size_t n)
{
    vdbhair::AllocationBudget* budget = vdbhair::AllocationBudget::current();
    if (budget) budget->charge(n);
    for (;;) {
        if (void* p = std::malloc(n ? n : 1)) {
            if (budget) budget->add(malloc_usable_size(p));
            return p;
        }
        std::new_handler handler = std::get_new_handler();
        if (!handler) throw std::bad_alloc();
        handler();
    }
}

VDBHAIR_HOOK void operator delete(void* p) noexcept
{
    if (!p) return;
    if (vdbhair::AllocationBudget* budget = vdbhair::AllocationBudget::current()) budget->release(malloc_usable_size(p));
    std::free(p);
}

VDBHAIR_HOOK void operator delete(void* p, std::size_t) noexcept { ::operator delete(p); }

VDBHAIR_HOOK void* operator new[](std::size_t n) { return ::operator new(n); }

VDBHAIR_HOOK void operator delete[](void* p) noexcept { ::operator delete(p); }

VDBHAIR_HOOK void operator delete[](void* p, std::size_t) noexcept { ::operator delete(p); }

VDBHAIR_HOOK void* operator new(std::size_t n, const std::nothrow_t&) noexcept
{
    try {
        return ::operator new(n);
    } catch (...) {
        return nullptr;
    }
}

VDBHAIR_HOOK void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return ::operator new(n, std::nothrow); }

VDBHAIR_HOOK void operator delete(void* p, const std::nothrow_t&) noexcept { ::operator delete(p); }

VDBHAIR_HOOK void operator delete[](void* p, const std::nothrow_t&) noexcept { ::operator delete(p); }
