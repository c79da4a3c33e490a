from mpi4py import MPI

from fenics_nl.domain.bracket import bracket_mesh
from fenics_nl.domain.meshes import graded_block


def cells(data):
    imap = data.mesh.topology.index_map(data.mesh.topology.dim)
    return MPI.COMM_WORLD.allreduce(imap.size_local)


def test_a_model_does_not_inherit_the_last_ones_mesh_options():
    # gmsh's mesh options are global: the bracket's MeshSizeMin (size/4) once made the
    # next punch block 40 times too coarse under the punch
    before = cells(graded_block(MPI.COMM_WORLD, 2, 100.0, 100.0, 0.05, 1.5, 0.05))
    bracket = cells(bracket_mesh(MPI.COMM_WORLD, 20.0))
    after = cells(graded_block(MPI.COMM_WORLD, 2, 100.0, 100.0, 0.05, 1.5, 0.05))
    assert after == before
    assert cells(bracket_mesh(MPI.COMM_WORLD, 20.0)) == bracket


def test_a_files_groups_are_checked_before_dolfinx_reads_its_cells(tmp_path):
    # dolfinx refuses a cell in two groups or in none by a count of cells (or a KeyError on
    # rank 0 alone): the readers of a user's file (bracket --mesh, case files) say which
    import gmsh

    from fenics_nl.domain.meshes import gmsh_error, group_error, start_model

    def boxes(*groups):
        start_model("boxes")
        gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
        gmsh.model.occ.addBox(1, 0, 0, 1, 1, 1)
        gmsh.model.occ.fragment([(3, 1)], [(3, 2)])
        gmsh.model.occ.synchronize()
        for k, (name, entities) in enumerate(groups, start=1):
            gmsh.model.addPhysicalGroup(3, entities, k, name=name)
        said = group_error(3)
        gmsh.model.remove()
        return said

    assert boxes(("solid", [1, 2])) is None
    assert boxes() == "no 3D physical group (dolfinx keeps only the cells of physical groups)"
    assert boxes(("solid", [1, 2]), ("again", [2])) == (
        "the 3D entity 2 is in the physical groups 'solid' and 'again' (each cell takes one "
        "group)")
    assert boxes(("solid", [1])) == ("the 3D entity 2 is in no physical group (each cell "
                                     "takes one group)")
    # gmsh's error, logged (a corrupt file) or raised (none), without gmsh's "Error :"
    corrupt = tmp_path / "corrupt.msh"
    corrupt.write_text("$MeshFormat\nthis is not a mesh\n")
    for path, said in ((corrupt, f"Error loading '{corrupt}'"),
                       (tmp_path / "none.msh", f"Unable to open file '{tmp_path}/none.msh'")):
        start_model("file")
        assert gmsh_error(lambda p=path: gmsh.open(str(p))) == said
        gmsh.model.remove()
    assert gmsh_error(lambda: None) is None
