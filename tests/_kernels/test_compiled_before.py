import os

import terramesh as tm
from terramesh._kernels import compiled_before, delaunay


def test_compiled_before_reads_numbas_cache_index_of_the_triangulation():
    tm.generate_mesh(tm.geometry.Disk((0, 0), 1), 0.3)  # compiled or loaded: the index is on disk either way
    index = delaunay.triangulate._cache._cache_file._index_path  # the numba internal it reads
    assert os.path.exists(index)
    assert compiled_before() is True
