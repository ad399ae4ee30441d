// Sequential Vecs whose entries live in storage with spare room, so that a mesh edit adding a
// few vertices reissues a nodal vector at the cost of what it adds (§7.4): the new, longer Vec
// is a new header over the same storage, where a new Vec of its own would copy every entry.
// When the storage is full it grows by half (its entries copied once then: amortised O(1) per
// entry added). The storage goes with the last Vec over it, so a handle to an earlier Vec stays
// valid; until the storage next grows, it shares its entries with the newer Vecs.
#pragma once

#include <petscvec.h>

namespace snede {

// *v ← a Vec of n zeros, block size block_size, over new storage of exactly n entries.
void create_growable_vec(PetscInt n, PetscInt block_size, Vec* v);

// Replaces *v (growable or not) by a growable Vec of n entries with *v's block size: its first
// min(n, size of *v) entries are *v's, the others zero. Destroys this reference to the old Vec.
void resize_growable_vec(Vec* v, PetscInt n);

// How many entries v's storage holds (its size if v is not growable).
PetscInt growable_capacity(Vec v);

}  // namespace snede
