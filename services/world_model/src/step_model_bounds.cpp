#include "step_model_bounds.hpp"

#include <BRepBndLib.hxx>
#include <Bnd_Box.hxx>

namespace rigger::world {

void describe_step_models(CellConfig& cell, const std::map<std::string, cad::Model>& read_models,
                          const std::filesystem::path& model_dir) {
  for (std::size_t i = 0; i < cell.entities.size(); ++i) {
    cell::CellEntity& entity = cell.entities[i];
    if (!entity.model || !entity.model->shape.empty() || entity.model->step.empty()) continue;
    cell::ObjectModel& model = *entity.model;
    const std::string pointer = "/entities/" + std::to_string(i) + "/model/step";
    Bnd_Box box;
    try {
      const auto read = read_models.find(entity.id);
      const cad::Model loaded = read != read_models.end() ? read->second : cad::read_step_file(model_dir / model.step);
      // The physics holds closed solids only: the same model is refused here, before any service takes it.
      if (const std::string problem = cad::solid_problem(loaded); !problem.empty())
        cell.fail(pointer, "a STEP model of closed solids", (model_dir / model.step).string() + ": " + problem);
      // The geometry's own box, not widened by the shape's tolerances.
      BRepBndLib::AddOptimal(loaded.shape(), box, false, false);
    } catch (const cad::CadError& error) {
      cell.fail(pointer, "a readable STEP file \"" + model.step + "\" (relative to " + model_dir.string() + ")",
                error.what());
    }
    if (box.IsVoid()) cell.fail(pointer, "a STEP model with geometry", "an empty model");
    double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
    box.Get(x0, y0, z0, x1, y1, z1);
    model.shape = "step";
    model.size_m = {x1 - x0, y1 - y0, z1 - z0};
  }
}

}  // namespace rigger::world
