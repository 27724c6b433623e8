#pragma once
// The furnished room of a realistic render (SceneOptions::furnished): what makes real indoor
// images hard for a feature tracker that the textured box room lacks. Walls and ceiling are
// plain paint with a few pictures on them, the floor a faded photo; texture comes in clusters
// (tables with objects on them, shelves of "books", boxes) between large plain surfaces
// (cupboard doors, table tops, walls); ceiling lamps make the brightness vary across the room.
#include <functional>
#include <random>

#include "synth/scene.hpp"

namespace hiveslam::synth {

// Adds the furniture, lamps and textures to `scene`, whose room bounds are set and which holds
// nothing yet. `clear(scene)` says whether the camera path still passes at a safe distance.
void furnishRoom(Scene& scene, const SceneOptions& options, const std::function<bool(const Scene&)>& clear,
                 std::mt19937_64& rng);

}  // namespace hiveslam::synth
