// Rendering DEM frames as speckle images (see render_run.hpp).
#include "render_run.hpp"

#include "errors.hpp"

namespace gs::dic {

void check_render_request(const RenderRequest& a) {
  parse_view(a.view);
  if (a.bits != 8 && a.bits != 16)
    throw InputError("--bits", "must be 8 or 16", std::to_string(a.bits));
  if (a.supersample < 1 || a.supersample > 16)
    throw InputError("--supersample", "must be in 1..16", std::to_string(a.supersample));
  if (!(a.noise >= 0.0 && a.noise < 1.0))
    throw InputError("--noise", "must be in [0, 1) (fraction of full scale)", value_str(a.noise));
}

Camera render_camera(const Frame& reference, const RenderRequest& a, const std::string& source) {
  return make_camera(reference, parse_view(a.view), a.px_per_d50, a.margin_d50, source);
}

RenderedFrame render_one(const Frame& reference, const Frame& f, const Camera& camera,
                         const RenderRequest& a) {
  RenderOptions ro;
  ro.supersample = a.supersample;
  ro.noise_sigma = a.noise * 255.0;
  ro.seed = a.seed;
  RenderedFrame out;
  const cv::Mat img = render_frame(f, camera, ro);
  const double full = a.bits == 8 ? 255.0 : 65535.0;
  img.convertTo(out.image, a.bits == 8 ? CV_8U : CV_16U, full / 255.0);  // rounds, saturates
  out.truth = ground_truth(reference, f, camera);
  return out;
}

}  // namespace gs::dic
