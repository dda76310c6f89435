// Prints a few values of the baked scene; the test checks them.
#include <cstdio>

#include "tiny.h"

int main() {
  const b2o::Scene& s = b2o::gen::tiny::scene;
  const b2o::Cloth& c = s.cloths[b2o::gen::tiny::cloth::Cloth];
  std::printf("scene %s vertices %u triangles %u objects %u masses %u springs %u pins %u dt %s texture %u\n", s.name,
              s.vertex_count, s.index_count / 3, s.object_count, c.mass_count, c.spring_count, c.pin_count,
              b2o::gen::tiny::param("dt", "none"), s.texture_count > 0 ? s.textures[0].size : 0u);
  return s.vertex_count == b2o::gen::tiny::vertex_count ? 0 : 1;
}
