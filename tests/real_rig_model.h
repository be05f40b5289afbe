// Fixtures of the plant-effect tests: the DFKI double pendulum A.0's rigid model (the lumped form of
// examples/real_rig/model.yaml, an exoskeleton alone) and an effect of the model file.
#pragma once
#include <string>

#include "model/lumped_params.h"

namespace exotwin {

inline LegParams RealRigModel() {
  LegParams p;
  p.L1 = 0.3;
  p.exo = {0.131785691, 0.023923745, 0.349117969, 0.111064801, 0, 0, 0.559380615, 0.604345947};
  return p;
}

inline Effect MakeEffect(const std::string& name, const std::string& joint, double value) {
  Effect e;
  e.name = name;
  e.joint = joint;
  e.value = value;
  return e;
}

}  // namespace exotwin
