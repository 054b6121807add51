// geogram_cvt IN OUT N: geogram's CVT surface remeshing (remesh_smooth) of IN at N points, written
// to OUT, with the pre- and post-processing vorpalite applies by default to a surface remesh:
// zero-area facets removed before, degree-3 vertices within 0.1% of the bounding-box diagonal
// removed and the normals oriented after. Built by eval/compare.py (build_geogram_cvt) against the
// static libgeogram.a of the `geogram` PyPI wheel, which is compiled without HLBFGS: the HLBFGS
// sources and geogram's lbfgs_optimizers.cpp from the same version's sdist are compiled in, and
// registered here, so remesh_smooth's Newton phase runs L-BFGS as vorpalite's does (without them
// geogram falls back to Lloyd iterations).

#include <geogram/basic/command_line.h>
#include <geogram/basic/command_line_args.h>
#include <geogram/basic/common.h>
#include <geogram/basic/logger.h>
#include <geogram/mesh/mesh.h>
#include <geogram/mesh/mesh_degree3_vertices.h>
#include <geogram/mesh/mesh_geometry.h>
#include <geogram/mesh/mesh_io.h>
#include <geogram/mesh/mesh_preprocessing.h>
#include <geogram/mesh/mesh_remesh.h>
#include <geogram/numerics/lbfgs_optimizers.h>

#include <cstdlib>
#include <iostream>

int main(int argc, char** argv) {
    using namespace GEO;
    if(argc != 4) {
        std::cerr << "usage: geogram_cvt IN OUT N" << std::endl;
        return 2;
    }
    GEO::initialize(GEO::GEOGRAM_INSTALL_ALL);
    geo_register_Optimizer_creator(HLBFGSOptimizer, "default");
    geo_register_Optimizer_creator(HLBFGSOptimizer, "HLBFGS");
    CmdLine::import_arg_group("standard");
    CmdLine::import_arg_group("algo");
    CmdLine::import_arg_group("remesh");
    CmdLine::import_arg_group("opt");
    Logger::instance()->set_quiet(true);

    Mesh M_in, M_out;
    if(!mesh_load(argv[1], M_in)) {
        return 1;
    }
    remove_small_facets(M_in, 1e-30);
    remesh_smooth(
        M_in, M_out, index_t(std::atoi(argv[3])), 3,
        CmdLine::get_arg_uint("opt:nb_Lloyd_iter"),
        CmdLine::get_arg_uint("opt:nb_Newton_iter"),
        CmdLine::get_arg_uint("opt:Newton_m")
    );
    if(M_out.facets.nb() == 0) {
        std::cerr << "geogram_cvt: empty output" << std::endl;
        return 1;
    }
    double deg3_dist = 0.001 * bbox_diagonal(M_out);
    while(remove_degree3_vertices(M_out, deg3_dist) != 0) {
    }
    orient_normals(M_out);
    return mesh_save(M_out, argv[2]) ? 0 : 1;
}
