#include "sequence_files.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

#include "impactdeck/common/atomic_file.hpp"
#include "impactdeck/common/csv_sidecar.hpp"
#include "impactdeck/common/error.hpp"
#include "impactdeck/common/xml_text.hpp"
#include "impactdeck/geometry/cad_shape.hpp"
#include "impactdeck/geometry/ellipsoid.hpp"
#include "impactdeck/geometry/ellipsoid_mesh.hpp"
#include "impactdeck/geometry/mesh_shape.hpp"
#include "impactdeck/plot/sequence_plot.hpp"

namespace impactdeck::scene::detail {
namespace fs = std::filesystem;

namespace {

// The body's surface triangles in its own frame (null when the shape has none).
const geometry::TriangleMesh* surface_of(const geometry::Shape& shape, geometry::TriangleMesh& storage) {
  if (const geometry::MeshShape* m = shape.triangle_mesh()) return &m->mesh();
  if (const auto* cad = dynamic_cast<const geometry::CadShape*>(&shape)) return &cad->triangulation().mesh();
  if (const geometry::Ellipsoid* e = shape.analytic_ellipsoid()) {
    const Eigen::Vector3d& a = e->semi_axes_m();
    storage = geometry::make_ellipsoid_mesh(a.x(), a.y(), a.z(), 3);
    return &storage;
  }
  return nullptr;
}

}  // namespace

void write_trajectory_csv(const fs::path& csv, const SequenceReport& sr, const std::string& scene_file) {
  const std::vector<std::string> columns = {"time_s", "x_m", "y_m", "z_m", "vx_m_s", "vy_m_s", "vz_m_s",
                                            "qw", "qx", "qy", "qz", "wx_rad_s", "wy_rad_s", "wz_rad_s",
                                            "height_m", "impact"};
  std::ostringstream o;
  o << std::setprecision(17);
  for (std::size_t k = 0; k < columns.size(); ++k) o << (k ? "," : "") << columns[k];
  o << "\n";
  // The impact column: the index of the impact a row's state is just before or just after, else -1.
  const auto& bounces = sr.result.bounces;
  std::size_t next = 0;
  for (const auto& t : sr.result.trajectory) {
    const sequence::BodyState& s = t.state;
    long impact = -1;
    while (next < bounces.size() && bounces[next].time_s < s.time_s) ++next;
    if (next < bounces.size() && bounces[next].time_s == s.time_s) impact = static_cast<long>(next);
    auto v = [](double x) { return x + 0.0; };
    o << v(s.time_s) << "," << v(s.centroid_m.x()) << "," << v(s.centroid_m.y()) << "," << v(s.centroid_m.z()) << ","
      << v(s.velocity_m_s.x()) << "," << v(s.velocity_m_s.y()) << "," << v(s.velocity_m_s.z()) << ","
      << v(s.orientation.w()) << "," << v(s.orientation.x()) << "," << v(s.orientation.y()) << ","
      << v(s.orientation.z()) << "," << v(s.angular_velocity_rad_s.x()) << "," << v(s.angular_velocity_rad_s.y())
      << "," << v(s.angular_velocity_rad_s.z()) << "," << v(t.gap_m) << "," << impact << "\n";
  }
  write_file_atomically(csv, o.str());
  write_csv_sidecar(csv, columns,
                    {{"scene", scene_file},
                     {"sequence", sr.spec->name},
                     {"body", sr.spec->body},
                     {"floor", sr.spec->floor},
                     {"content", "the body's centroid (world, m), velocity, orientation (unit quaternion, own frame "
                                 "-> world), angular velocity (world) and the height of its lowest point above the "
                                 "floor; impact: the index of the impact a row is just before or after (-1: flight)"}});
}

std::size_t write_vtk_series(const fs::path& pvd, const fs::path& frames_dir, const std::string& frames_name,
                             const SequenceReport& sr, const contact::PreparedBody& body, LengthUnit unit) {
  geometry::TriangleMesh storage;
  const geometry::TriangleMesh* mesh = surface_of(*body.shape, storage);
  const auto& traj = sr.result.trajectory;
  if (!mesh || mesh->triangles.empty() || traj.empty()) return 0;
  std::size_t frames = std::min<std::size_t>({kMaxVtkFrames, traj.size(),
                                              std::max<std::size_t>(2, kMaxVtkTriangles / mesh->triangles.size())});
  frames = std::max<std::size_t>(1, frames);
  std::error_code ec;
  fs::create_directories(frames_dir, ec);
  if (ec) throw InputError(frames_dir.string(), "folder", "cannot create: " + ec.message());
  const double scale = 1.0 / metres_per(unit);
  std::ostringstream collection;
  collection << "<?xml version=\"1.0\"?>\n<!-- "
             << xml_comment_text("impactdeck: sequence '" + sr.spec->name + "', body '" + sr.spec->body +
                                 "'; positions in " + to_string(unit) + ", times in s")
             << " -->\n"
             << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n<Collection>\n";
  collection << std::setprecision(17);
  for (std::size_t f = 0; f < frames; ++f) {
    const std::size_t k = frames == 1 ? 0 : f * (traj.size() - 1) / (frames - 1);
    const sequence::BodyState& s = traj[k].state;
    const geometry::Pose pose = s.pose(body.volume.centroid_m);
    std::ostringstream v;
    v << std::setprecision(9);
    v << "<?xml version=\"1.0\"?>\n<!-- positions in " << to_string(unit) << " -->\n"
      << "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\">\n<PolyData>\n"
      << "<FieldData><DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">"
      << std::setprecision(17) << s.time_s << std::setprecision(9) << "</DataArray></FieldData>\n"
      << "<Piece NumberOfPoints=\"" << mesh->vertices_m.size() << "\" NumberOfPolys=\"" << mesh->triangles.size()
      << "\">\n<Points><DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n";
    for (const Eigen::Vector3d& p : mesh->vertices_m) {
      const Eigen::Vector3d w = pose.to_world(p) * scale;
      v << w.x() + 0.0 << " " << w.y() + 0.0 << " " << w.z() + 0.0 << "\n";
    }
    v << "</DataArray></Points>\n<Polys><DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n";
    for (const auto& t : mesh->triangles) v << t[0] << " " << t[1] << " " << t[2] << "\n";
    v << "</DataArray><DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n";
    for (std::size_t i = 1; i <= mesh->triangles.size(); ++i) v << 3 * i << (i % 16 ? " " : "\n");
    v << "\n</DataArray></Polys>\n</Piece>\n</PolyData>\n</VTKFile>\n";
    std::ostringstream name;
    name << "frame_" << std::setw(4) << std::setfill('0') << f << ".vtp";
    write_file_atomically(frames_dir / name.str(), v.str());
    collection << "<DataSet timestep=\"" << s.time_s << "\" part=\"0\" file=\"" << xml_escape(frames_name + "/" + name.str())
               << "\"/>\n";
  }
  collection << "</Collection>\n</VTKFile>\n";
  write_file_atomically(pvd, collection.str());
  return frames;
}

std::string sequence_svg(const SequenceReport& sr, LengthUnit unit) {
  plot::SequencePlotData d;
  d.title = "Drop sequence '" + sr.spec->name + "': " + sr.spec->body + " on " + sr.spec->floor;
  for (const auto& t : sr.result.trajectory) {
    d.time_s.push_back(t.state.time_s);
    d.height_m.push_back(t.gap_m);
  }
  for (const auto& b : sr.result.bounces) {
    d.impact_time_s.push_back(b.time_s);
    d.impact_max_force_N.push_back(b.max_force_N());
  }
  d.length_unit = to_string(unit);
  d.metres_per_unit = metres_per(unit);
  return plot::to_svg(plot::sequence_drawing(d));
}

}  // namespace impactdeck::scene::detail
