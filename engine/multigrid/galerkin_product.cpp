#include "multigrid/galerkin_product.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "core/csr_matrix.hpp"
#include "core/error.hpp"

namespace snede {
namespace {

class PetscGalerkin final : public CoarseProduct {
 public:
  PetscGalerkin(Mat A, Mat P) {
    SNEDE_PETSC(MatProductCreate(A, P, nullptr, product_.out()));
    SNEDE_PETSC(MatProductSetType(product_, MATPRODUCT_PtAP));
    SNEDE_PETSC(MatProductSetAlgorithm(product_, MATPRODUCTALGORITHMRAP));
    SNEDE_PETSC(MatProductSetFill(product_, PETSC_DEFAULT));
    SNEDE_PETSC(MatProductSetFromOptions(product_));
    SNEDE_PETSC(MatProductSymbolic(product_));
    SNEDE_PETSC(MatProductNumeric(product_));
    SNEDE_PETSC(MatSetOption(product_, MAT_SYMMETRIC, PETSC_TRUE));
  }
  void recompute() override { SNEDE_PETSC(MatProductNumeric(product_)); }
  Mat matrix() const override { return product_; }

 private:
  MatHandle product_;
};

// A's arrays (csr_matrix.hpp), which must be vertex blocks: SeqBAIJ with block size d.
class VertexBlocks : public CsrView {
 public:
  VertexBlocks(Mat A, int d) : CsrView(A) {
    PetscInt block_size = 0;
    SNEDE_PETSC(MatGetBlockSize(A, &block_size));
    if (!blocked || block_size != d)
      throw std::logic_error("a Galerkin product by vertex blocks needs a SeqBAIJ matrix of block size " +
                             std::to_string(d));
  }
};

// Pᵀ A P vertex block by vertex block, in two passes: the rows of A·P of each fine vertex (its
// neighbours' blocks times theirs of P, gathered per coarse copy), then each copy's row of the
// product (its members' blocks of P, transposed, times their rows of A·P). Dense accumulators
// over the copies; the structure of both is found once.
class BlockGalerkin final : public CoarseProduct {
 public:
  BlockGalerkin(Mat A, const BlockInterpolation& P) : A_(A), P_(P), d_(P.dim) {
    const VertexBlocks a(A, d_);
    const auto n = static_cast<PetscInt>(P.start.size()) - 1;
    if (a.rows != n) throw std::logic_error("block Galerkin product: A and P do not match");
    // A's vertex structure: its block rows.
    a_start_.assign(a.start, a.start + n + 1);
    a_neighbour_.assign(a.column, a.column + a.start[n]);
    // A free vertex's block is its weight times the identity (the copy's d columns): one
    // multiplication per entry of A's block instead of d.
    scalar_.assign(P.copy.size(), 0.0);
    is_scalar_.assign(P.copy.size(), 0);
    for (std::size_t t = 0; t < P.copy.size(); ++t) {
      const double* block = P.block.data() + t * d_ * d_;
      bool identity_times = P.columns(P.copy[t]) == d_;
      for (int i = 0; i < d_ && identity_times; ++i)
        for (int j = 0; j < d_; ++j) identity_times = identity_times && block[i * d_ + j] == (i == j ? block[0] : 0.0);
      if (identity_times) {
        scalar_[t] = block[0];
        is_scalar_[t] = 1;
      }
    }
    const PetscInt copies = P.n_copies();
    std::vector<PetscInt> marked(static_cast<std::size_t>(copies), -1);
    // A·P's copies per fine vertex.
    ap_start_.assign(static_cast<std::size_t>(n) + 1, 0);
    for (PetscInt v = 0; v < n; ++v) {
      for (std::size_t k = a_start_[v]; k < a_start_[v + 1]; ++k)
        for (std::size_t t = P.start[a_neighbour_[k]]; t < P.start[a_neighbour_[k] + 1]; ++t)
          if (marked[P.copy[t]] != v) {
            marked[P.copy[t]] = v;
            ap_copy_.push_back(P.copy[t]);
          }
      ap_start_[v + 1] = ap_copy_.size();
    }
    ap_value_.resize(ap_copy_.size() * d_ * d_);
    // Each copy's members: P's entries of that copy, by vertex.
    member_start_.assign(static_cast<std::size_t>(copies) + 1, 0);
    for (PetscInt c : P.copy) ++member_start_[c + 1];
    for (PetscInt c = 0; c < copies; ++c) member_start_[c + 1] += member_start_[c];
    member_entry_.resize(P.copy.size());
    member_vertex_.resize(P.copy.size());
    std::vector<std::size_t> next(member_start_.begin(), member_start_.end() - 1);
    for (PetscInt v = 0; v < n; ++v)
      for (std::size_t t = P.start[v]; t < P.start[v + 1]; ++t) {
        member_entry_[next[P.copy[t]]] = t;
        member_vertex_[next[P.copy[t]]++] = v;
      }
    // The product's copies per copy (sorted), then its scalar rows: copy c's p-th column is
    // coarse unknown first_column[c] + p.
    std::fill(marked.begin(), marked.end(), -1);
    product_start_.assign(static_cast<std::size_t>(copies) + 1, 0);
    for (PetscInt c = 0; c < copies; ++c) {
      const std::size_t first = product_copy_.size();
      for (std::size_t m = member_start_[c]; m < member_start_[c + 1]; ++m) {
        const PetscInt v = member_vertex_[m];
        for (std::size_t k = ap_start_[v]; k < ap_start_[v + 1]; ++k)
          if (marked[ap_copy_[k]] != c) {
            marked[ap_copy_[k]] = c;
            product_copy_.push_back(ap_copy_[k]);
          }
      }
      std::sort(product_copy_.begin() + static_cast<std::ptrdiff_t>(first), product_copy_.end());
      product_start_[c + 1] = product_copy_.size();
    }
    auto arrays = std::make_unique<CsrArrays>();
    const PetscInt unknowns = P.first_column.back();
    arrays->row_start.assign(static_cast<std::size_t>(unknowns) + 1, 0);
    for (PetscInt c = 0; c < copies; ++c) {
      PetscInt length = 0;
      for (std::size_t k = product_start_[c]; k < product_start_[c + 1]; ++k) length += P.columns(product_copy_[k]);
      for (PetscInt p = 0; p < P.columns(c); ++p) {
        const PetscInt row = P.first_column[c] + p;
        arrays->row_start[row + 1] = arrays->row_start[row] + length;
        for (std::size_t k = product_start_[c]; k < product_start_[c + 1]; ++k)
          for (PetscInt q = 0; q < P.columns(product_copy_[k]); ++q)
            arrays->columns.push_back(P.first_column[product_copy_[k]] + q);
      }
    }
    arrays->values.assign(arrays->columns.size(), 0.0);
    product_arrays_ = arrays.get();
    product_ = matrix_owning(std::move(arrays), unknowns, unknowns);
    SNEDE_PETSC(MatSetOption(product_, MAT_SYMMETRIC, PETSC_TRUE));
    recompute();
  }

  void recompute() override {
    const VertexBlocks a(A_, d_);
    if (static_cast<std::size_t>(a.start[a.rows]) != a_neighbour_.size())
      throw std::logic_error("block Galerkin product: the fine matrix changed its structure since it was set up");
    if (d_ == 3) {
      multiply<3>(a);
    } else {
      multiply<2>(a);
    }
    // Written in place: assembling gives the matrix a new state, so that the coarse solver
    // factorises it again (numerically only: same structure).
    SNEDE_PETSC(MatAssemblyBegin(product_, MAT_FINAL_ASSEMBLY));
    SNEDE_PETSC(MatAssemblyEnd(product_, MAT_FINAL_ASSEMBLY));
  }
  Mat matrix() const override { return product_; }

 private:
  template <int D>
  void multiply(const VertexBlocks& a) {
    constexpr int DD = D * D;
    const auto n = static_cast<PetscInt>(P_.start.size()) - 1;
    std::vector<double> accumulator(static_cast<std::size_t>(P_.n_copies()) * DD, 0.0);
    // A·P, vertex by vertex: Σ over neighbours w of A_vw P_w.
    double A_block[DD];  // row by row
    for (PetscInt v = 0; v < n; ++v) {
      for (std::size_t k = a_start_[v]; k < a_start_[v + 1]; ++k) {
        for (int i = 0; i < D; ++i)
          for (int j = 0; j < D; ++j) A_block[i * D + j] = a.value[k * DD + j * D + i];
        const PetscInt w = a_neighbour_[k];
        for (std::size_t t = P_.start[w]; t < P_.start[w + 1]; ++t) {
          double* sum = accumulator.data() + static_cast<std::size_t>(P_.copy[t]) * DD;
          if (is_scalar_[t]) {
            const double s = scalar_[t];
            for (int e = 0; e < DD; ++e) sum[e] += s * A_block[e];
            continue;
          }
          const double* block = P_.block.data() + t * DD;
          for (int i = 0; i < D; ++i)
            for (int m = 0; m < D; ++m)
              for (int j = 0; j < D; ++j) sum[i * D + j] += A_block[i * D + m] * block[m * D + j];
        }
      }
      for (std::size_t k = ap_start_[v]; k < ap_start_[v + 1]; ++k) {
        double* sum = accumulator.data() + static_cast<std::size_t>(ap_copy_[k]) * DD;
        std::copy(sum, sum + DD, ap_value_.begin() + static_cast<std::ptrdiff_t>(k * DD));
        std::fill(sum, sum + DD, 0.0);
      }
    }
    // Pᵀ (A·P), copy by copy: Σ over members v of P_v,cᵀ (A·P)_v.
    std::vector<PetscScalar>& values = product_arrays_->values;
    for (PetscInt c = 0; c < P_.n_copies(); ++c) {
      for (std::size_t m = member_start_[c]; m < member_start_[c + 1]; ++m) {
        const PetscInt v = member_vertex_[m];
        const std::size_t t = member_entry_[m];
        const double* block = P_.block.data() + t * DD;
        for (std::size_t k = ap_start_[v]; k < ap_start_[v + 1]; ++k) {
          double* sum = accumulator.data() + static_cast<std::size_t>(ap_copy_[k]) * DD;
          const double* ap = ap_value_.data() + k * DD;
          if (is_scalar_[t]) {
            const double s = scalar_[t];
            for (int e = 0; e < DD; ++e) sum[e] += s * ap[e];
            continue;
          }
          for (int p = 0; p < D; ++p)
            for (int i = 0; i < D; ++i)
              for (int q = 0; q < D; ++q) sum[p * D + q] += block[i * D + p] * ap[i * D + q];
        }
      }
      for (PetscInt p = 0; p < P_.columns(c); ++p) {
        PetscInt at = product_arrays_->row_start[P_.first_column[c] + p];
        for (std::size_t k = product_start_[c]; k < product_start_[c + 1]; ++k) {
          const double* sum = accumulator.data() + static_cast<std::size_t>(product_copy_[k]) * DD;
          for (PetscInt q = 0; q < P_.columns(product_copy_[k]); ++q) values[at++] = sum[p * D + q];
        }
      }
      for (std::size_t k = product_start_[c]; k < product_start_[c + 1]; ++k) {
        double* sum = accumulator.data() + static_cast<std::size_t>(product_copy_[k]) * DD;
        std::fill(sum, sum + DD, 0.0);
      }
    }
  }

  Mat A_;
  const BlockInterpolation& P_;
  int d_;
  std::vector<double> scalar_;    // per entry of P: s where its block is s·I
  std::vector<char> is_scalar_;
  std::vector<std::size_t> a_start_;  // per fine vertex: its neighbours in A (A's block rows)
  std::vector<PetscInt> a_neighbour_;
  std::vector<std::size_t> ap_start_;  // per fine vertex: the copies of its row of A·P
  std::vector<PetscInt> ap_copy_;
  std::vector<double> ap_value_;  // d × d per entry
  std::vector<std::size_t> member_start_;  // per copy: the entries of P that belong to it
  std::vector<std::size_t> member_entry_;
  std::vector<PetscInt> member_vertex_;
  std::vector<std::size_t> product_start_;  // per copy: the copies of its row of the product
  std::vector<PetscInt> product_copy_;
  CsrArrays* product_arrays_ = nullptr;  // owned by product_
  MatHandle product_;
};

}  // namespace

std::unique_ptr<CoarseProduct> petsc_galerkin_product(Mat A, Mat P) { return std::make_unique<PetscGalerkin>(A, P); }

std::unique_ptr<CoarseProduct> block_galerkin_product(Mat A, const BlockInterpolation& blocks) {
  return std::make_unique<BlockGalerkin>(A, blocks);
}

}  // namespace snede
