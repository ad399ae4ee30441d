#include "fem/element_stream.hpp"

namespace snede {
namespace {

template <int D>
ElementBlock<D> free_block() {
  ElementBlock<D> block;
  block.reference.Z_inv = Tensor<Batch, D>::Identity();
  block.reference.measure = 0.0;
  for (auto& corner : block.rows) corner.fill(0);
  return block;
}

}  // namespace

template <int D>
void ElementStream<D>::reserve_ids(ElementId capacity) {
  const std::size_t n_blocks = (static_cast<std::size_t>(capacity) + batch_width - 1) / batch_width;
  if (n_blocks > blocks_.size()) blocks_.resize(n_blocks, free_block<D>());
}

template <int D>
void ElementStream<D>::store(ElementId e, const Vertices& vertices, const ElementReference<D>& reference) {
  ElementBlock<D>& block = block_of(e);
  const int lane = e % batch_width;
  auto set_lane = [lane](Batch& batch, double value) {
    batch = Batch::from_lanes([&](int l) { return l == lane ? value : batch[l]; });
  };
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) set_lane(block.reference.Z_inv(i, j), reference.Z_inv(i, j));
  set_lane(block.reference.measure, reference.measure);
  for (int j = 0; j <= D; ++j) block.rows[j][lane] = D * vertices[j];
}

template <int D>
void ElementStream<D>::release(ElementId e) {
  const ElementReference<D> identity{Tensor<double, D>::Identity(), 0.0};
  store(e, Vertices{}, identity);
}

template <int D>
typename ElementStream<D>::Vertices ElementStream<D>::vertices(ElementId e) const {
  Vertices v;
  for (int j = 0; j <= D; ++j) v[j] = block_of(e).rows[j][e % batch_width] / D;
  return v;
}

template <int D>
ElementReference<D> ElementStream<D>::reference(ElementId e) const {
  const ElementReference<D, Batch>& block = block_of(e).reference;
  const int lane = e % batch_width;
  return {lane_of(block.Z_inv, lane), block.measure[lane]};
}

template class ElementStream<2>;
template class ElementStream<3>;

}  // namespace snede
