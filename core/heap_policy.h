// How the process's heap returns freed memory to the system.
//
// KeepFreedMemoryForReuse() is called by the commands that analyse whole records (`exotwin
// diagnose`, `exotwin predict`), not globally: they allocate and free many record-sized vectors (one
// column of a 10 min, 1 kHz record is 5 MB), and with the allocator's defaults each of them is
// mapped, zeroed page by page and unmapped again. Afterwards blocks up to 32 MB come from the heap
// and freed memory stays there for the next one. Results are unchanged; the peak memory stays that
// of the largest set of live vectors, give or take the heap's reuse pattern (+1 to +4 MB measured on
// 10 min at 1 kHz).
#pragma once

namespace exotwin {

void KeepFreedMemoryForReuse();

// Gives the pages of the heap's free blocks back to the system (malloc_trim): called between the
// stages of a whole-record analysis, so that the blocks one stage freed do not stay resident while
// the next one lays out its own (the peak memory stays that of the live vectors).
void ReturnFreedMemory();

}  // namespace exotwin
