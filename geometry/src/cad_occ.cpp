// OpenCASCADE's readers and adaptive mass properties for the CAD plugin (cad_occ.hpp).
#include "cad_occ.hpp"

#include <BRepBndLib.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRep_Tool.hxx>
#include <Poly_PolygonOnTriangulation.hxx>
#include <Poly_Triangulation.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Vertex.hxx>
#include <BRepGProp.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Reader.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Controller.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Shape.hxx>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

#include "impactdeck/common/error.hpp"

namespace impactdeck::geometry::detail {
namespace fs = std::filesystem;

namespace {

TopoDS_Shape read_shape(const fs::path& file, CadFormat format) {
  const std::string where = file.string();
  occ_init_translators();
  if (format == CadFormat::brep) {
    TopoDS_Shape s;
    BRep_Builder b;
    if (!BRepTools::Read(s, file.string().c_str(), b) || s.IsNull()) {
      throw InputError(where, "mass properties", "OpenCASCADE cannot read the BREP file");
    }
    return s;
  }
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  if (format == CadFormat::step) {
    STEPControl_Reader r;
    if (r.ReadFile(file.string().c_str()) != IFSelect_RetDone) {
      throw InputError(where, "mass properties", "OpenCASCADE cannot read the STEP file");
    }
    r.TransferRoots();
    return r.OneShape();
  }
  IGESControl_Reader r;
  if (r.ReadFile(file.string().c_str()) != IFSelect_RetDone) {
    throw InputError(where, "mass properties", "OpenCASCADE cannot read the IGES file");
  }
  r.TransferRoots();
  return r.OneShape();
}

}  // namespace

void occ_init_translators() {
  STEPControl_Controller::Init();
  IGESControl_Controller::Init();
}

OccMass occ_mass_properties(const fs::path& file, CadFormat format, double eps) {
  const std::string where = file.string();
  try {
    const TopoDS_Shape shape = read_shape(file, format);
    OccMass out;
    // Each solid about the middle of its bounding box (OpenCASCADE integrates the moments about
    // the system's location: far from the part they lose digits when moved to the centre).
    struct Part {
      double m;
      Eigen::Vector3d c;
      Eigen::Matrix3d J;
    };
    std::vector<Part> parts;
    for (TopExp_Explorer ex(shape, TopAbs_SOLID); ex.More(); ex.Next()) {
      Bnd_Box box;
      BRepBndLib::Add(ex.Current(), box);
      if (box.IsVoid()) throw InputError(where, "mass properties", "a solid without geometry (empty bounding box)");
      double x0, y0, z0, x1, y1, z1;
      box.Get(x0, y0, z0, x1, y1, z1);
      GProp_GProps props(gp_Pnt(0.5 * (x0 + x1), 0.5 * (y0 + y1), 0.5 * (z0 + z1)));
      const double err = BRepGProp::VolumeProperties(ex.Current(), props, eps, true);
      const double m = props.Mass();
      if (!(m > 0)) {
        throw InputError(where, "solid " + std::to_string(out.solids + 1), "has no positive volume (is it closed?)");
      }
      const gp_Pnt c = props.CentreOfMass();
      const gp_Mat I = props.MatrixOfInertia();  // about the centre of mass
      Eigen::Matrix3d J;
      for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k) J(i, k) = I.Value(i + 1, k + 1);
      }
      parts.push_back({m, Eigen::Vector3d(c.X(), c.Y(), c.Z()), J});
      out.relative_error = std::max(out.relative_error, std::isfinite(err) ? std::abs(err) : 1.0);
      ++out.solids;
    }
    if (parts.empty()) return out;
    Eigen::Vector3d first = Eigen::Vector3d::Zero();
    for (const auto& p : parts) {
      out.volume += p.m;
      first += p.m * p.c;
    }
    out.centre = first / out.volume;
    for (const auto& p : parts) {
      const Eigen::Vector3d r = p.c - out.centre;
      out.inertia += p.J + p.m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
    }
    out.inertia = 0.5 * (out.inertia + out.inertia.transpose());
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(shape, TopAbs_FACE, faces);
    for (int i = 1; i <= faces.Extent(); ++i) {
      GProp_GProps a;
      BRepGProp::SurfaceProperties(faces(i), a, eps);
      out.area += a.Mass();
    }
    return out;
  } catch (const Standard_Failure& e) {
    throw InputError(where, "mass properties",
                     std::string("OpenCASCADE stopped with an error of its own: ") + e.GetMessageString());
  }
}

OccTriangulation occ_triangulate(const fs::path& file, CadFormat format, double deflection, double angle_rad) {
  const std::string where = file.string();
  try {
    const TopoDS_Shape shape = read_shape(file, format);
    BRepMesh_IncrementalMesh mesher(shape, deflection, false, angle_rad, false);
    if (!mesher.IsDone()) throw InputError(where, "triangulation", "OpenCASCADE's mesher failed");
    TopTools_IndexedMapOfShape faces, edges, vertices;
    TopExp::MapShapes(shape, TopAbs_FACE, faces);
    TopExp::MapShapes(shape, TopAbs_EDGE, edges);
    TopExp::MapShapes(shape, TopAbs_VERTEX, vertices);
    OccTriangulation out;
    // Welding: a polygon's end node is its B-rep vertex (-vertex index, 0); an inner node is
    // (edge index, its parameter on the edge, or its position when the polygon has none). Each
    // edge is discretised once, so every face bounded by it has the same nodes on it.
    std::map<std::pair<int, double>, int> edge_node;
    for (int fi = 1; fi <= faces.Extent(); ++fi) {
      const TopoDS_Face& face = TopoDS::Face(faces(fi));
      TopLoc_Location loc;
      const Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(face, loc);
      if (tri.IsNull()) {
        throw InputError(where, "triangulation", "OpenCASCADE left face " + std::to_string(fi) + " untriangulated");
      }
      const gp_Trsf t = loc.Transformation();
      std::vector<int> node_of(static_cast<std::size_t>(tri->NbNodes()) + 1, -1);
      for (TopExp_Explorer ex(face, TopAbs_EDGE); ex.More(); ex.Next()) {
        const TopoDS_Edge& e = TopoDS::Edge(ex.Current());
        const Handle(Poly_PolygonOnTriangulation) poly = BRep_Tool::PolygonOnTriangulation(e, tri, loc);
        if (poly.IsNull()) continue;
        const int ei = edges.FindIndex(e);
        const int n = poly->NbNodes();
        for (int k = 1; k <= n; ++k) {
          const int local = poly->Node(k);
          std::pair<int, double> key{ei, poly->HasParameters() ? poly->Parameter(k) : static_cast<double>(k)};
          if (k == 1 || k == n) {
            const TopoDS_Vertex v = k == 1 ? TopExp::FirstVertex(e) : TopExp::LastVertex(e);
            if (!v.IsNull()) key = {-vertices.FindIndex(v), 0.0};
          }
          const auto found = edge_node.find(key);
          int g = found != edge_node.end() ? found->second : node_of[local];
          if (g < 0) {
            g = static_cast<int>(out.nodes.size());
            const gp_Pnt p = tri->Node(local).Transformed(t);
            out.nodes.emplace_back(p.X(), p.Y(), p.Z());
          }
          edge_node.emplace(key, g);
          node_of[local] = g;
        }
      }
      for (int i = 1; i <= tri->NbNodes(); ++i) {
        if (node_of[i] >= 0) continue;
        const gp_Pnt p = tri->Node(i).Transformed(t);
        node_of[i] = static_cast<int>(out.nodes.size());
        out.nodes.emplace_back(p.X(), p.Y(), p.Z());
      }
      const bool reversed = face.Orientation() == TopAbs_REVERSED;
      double best = -1;
      Eigen::Vector3d probe = Eigen::Vector3d::Zero();
      for (int i = 1; i <= tri->NbTriangles(); ++i) {
        int a, b, c;
        tri->Triangle(i).Get(a, b, c);
        if (reversed) std::swap(b, c);
        const std::array<int, 3> tr{node_of[a], node_of[b], node_of[c]};
        if (tr[0] == tr[1] || tr[1] == tr[2] || tr[0] == tr[2]) continue;  // collapsed at a pole
        out.triangles.push_back(tr);
        out.triangle_face.push_back(fi - 1);
        const Eigen::Vector3d &x0 = out.nodes[tr[0]], &x1 = out.nodes[tr[1]], &x2 = out.nodes[tr[2]];
        const double area = (x1 - x0).cross(x2 - x0).norm();
        if (area > best) best = area, probe = (x0 + x1 + x2) / 3.0;
      }
      out.face_probe.push_back(probe);
    }
    return out;
  } catch (const Standard_Failure& e) {
    throw InputError(where, "triangulation",
                     std::string("OpenCASCADE stopped with an error of its own: ") + e.GetMessageString());
  }
}

}  // namespace impactdeck::geometry::detail
