#include "core/heap_policy.h"

#include <malloc.h>

namespace exotwin {

void KeepFreedMemoryForReuse() {
  mallopt(M_MMAP_THRESHOLD, 32 << 20);  // glibc's largest
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

void ReturnFreedMemory() { malloc_trim(0); }

}  // namespace exotwin
