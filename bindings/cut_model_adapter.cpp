#include "cut_model_adapter.hpp"

#include <memory>
#include <stdexcept>
#include <vector>

#include "core/petsc_util.hpp"
#include "problem/piece_holding.hpp"

namespace snede {

DisplacementSource displacement_of(Model* model, const Mesh& mesh, const std::string& cutter) {
  if (!model) return {};
  if (&model->body().mesh() != &mesh) throw std::invalid_argument(cutter + ": the model's body is on another mesh");
  return [model] {
    auto view = std::make_shared<const ReadView>(model->displacement());
    return DisplacementRead{view->span(), view};
  };
}

CutBody cut_body_of(Model* model, const Mesh& mesh, const std::string& cutter) {
  CutBody body;
  body.displacement = displacement_of(model, mesh, cutter);
  if (!model) return body;
  body.exclusive_use = &model->exclusive_use();
  body.is_support = [model](VertexId v) { return model->constraints().constrained_components(v) > 0; };
  body.free_pieces = [model] {
    std::vector<ElementId> cells;
    for (const LoosePiece& piece : PieceHolding(model->body().mesh()).loose_pieces(model->constraints()))
      cells.push_back(piece.first_cell);
    return cells;
  };
  body.hold_free_piece = [model](std::span<const VertexId> face) {
    const int dim = model->dim();
    std::vector<double> values;
    {
      const ReadView u(model->displacement());
      for (VertexId v : face)
        for (int k = 0; k < dim; ++k) values.push_back(u.span()[static_cast<std::size_t>(dim) * v + k]);
    }
    model->fix(face, values);
  };
  return body;
}

}  // namespace snede
