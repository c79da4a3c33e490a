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
