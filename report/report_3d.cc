#include "report/report_3d.h"

#include <sstream>

#include "report/report_html.h"

namespace bouncefit {

std::string View3dSection(const std::filesystem::path& dir, const std::string& beside) {
  const auto glb = dir / "fitted_ball.glb";
  if (!std::filesystem::exists(glb)) return {};
  std::ostringstream h;
  h << "<h2>The fitted ball in 3D</h2>\n";
  const auto script = EmbeddedViewerScript("view3d.bundle.js");
  if (!script) {
    h << "<p class=\"note\">fitted_ball.glb is here, but this bouncefit was built without "
         "three.js (scripts/setup installs it), so the page has no 3D view.</p>\n";
    return h.str();
  }
  h << "<div class=\"view3d-row\">\n"
    << "<div class=\"view3d\" id=\"view3d\" data-glb=\"fitted-ball-glb\" data-state=\"loading\">\n"
    << "<canvas width=\"540\" height=\"440\"></canvas>\n"
    << "<div class=\"view3d-controls\"><button type=\"button\">Pause</button> "
    << "<input type=\"range\" min=\"0\" max=\"1\" step=\"0.001\" value=\"0\" "
       "aria-label=\"real time since the fit's start apex (s)\"> <span class=\"view3d-time\">loading</span></div>\n"
    << "<p class=\"note\">fitted_ball.glb: the fitted ball (orange) dropped from the apex the "
       "fit started from"
    << " and the tracked ball (blue, beside it) from the same apex, in real seconds, on the floor at "
       "y = 0; drag to turn the view. The same file opens in Blender (File &gt; Import &gt; "
       "glTF 2.0).</p>\n"
    << "</div>\n" << beside << "</div>\n"
    << "<script type=\"application/octet-stream\" id=\"fitted-ball-glb\">"
    << Base64Encode(ReadBinary(glb)) << "</script>\n"
    << "<script>\n" << *script << "\n</script>\n";
  return h.str();
}

}  // namespace bouncefit
