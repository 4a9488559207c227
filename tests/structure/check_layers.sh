#!/usr/bin/env bash
# The layering rules (docs/architecture.md, "Layers"), checked on the sources and on the built
# core library. Usage: check_layers.sh SOURCE_DIR LIBDEM2D_CORE.a
#   core/      physics: includes only core/, the C++ standard library and Eigen; no MPI, HDF5,
#              TOML, METIS or fmt; its library references no MPI or HDF5 symbol;
#   parallel/  may include core/ and parallel/ (and mpi.h, metis.h), never io/ or app/;
#   io/        may include core/, parallel/ and io/, never app/; calls no MPI function itself
#              (the MPI_Comm handle and H5Pset_fapl_mpio for collective HDF5 are allowed);
#   app/       calls no MPI function but MPI_Finalize, MPI_Comm_rank, MPI_Comm_size (MPI starts
#              with parallel's mpi::init).
# Also: the tree of src/ in README.md names exactly the folders of src/ and src/core.
# Prints every violation with its file and line; exit 1 if there is any.
set -u
src=$1/src
core_lib=$2
failures=0
violation() { echo "layer violation: $1"; failures=$((failures + 1)); }

# Project includes ("dir/file.hpp") that a layer may not use.
check_includes() {
  local dir=$1 allowed=$2
  while IFS= read -r hit; do
    violation "$hit (src/$dir may include only $allowed)"
  done < <(grep -rnHE --include='*.hpp' --include='*.cpp' '^\s*#\s*include\s*"' "$src/$dir" |
           grep -vE "#\s*include\s*\"($allowed)/" | sed "s|$src/|src/|")
}
check_includes core 'core'
check_includes parallel 'core|parallel'
check_includes io 'core|parallel|io'

# Third-party headers the physics must not see.
while IFS= read -r hit; do
  violation "$hit (the physics sees no MPI, HDF5, TOML, METIS or fmt)"
done < <(grep -rnHE --include='*.hpp' --include='*.cpp' \
           '^\s*#\s*include\s*<(mpi|hdf5|H5[A-Za-z]*|metis|toml\+\+/|fmt/|CLI/)' "$src"/core |
         sed "s|$src/|src/|")
while IFS= read -r hit; do
  violation "$hit (an MPI call in the physics)"
done < <(grep -rnHE --include='*.hpp' --include='*.cpp' '\bMPI_[A-Za-z_]+' "$src"/core |
         sed "s|$src/|src/|")

# MPI calls outside src/parallel.
while IFS= read -r hit; do
  violation "$hit (io calls no MPI function: use the parallel layer)"
done < <(grep -nHE '\bMPI_[A-Z][a-z_]+\s*\(' "$src"/io/*.{hpp,cpp} | sed "s|$src/|src/|")
while IFS= read -r hit; do
  violation "$hit (main.cpp starts and ends MPI only)"
done < <(grep -nHE '\bMPI_[A-Z][a-z_]+\s*\(' "$src"/app/*.cpp |
         grep -vE '\bMPI_(Finalize|Comm_rank|Comm_size)\s*\(' | sed "s|$src/|src/|")

# The built core library: no undefined MPI or HDF5 symbol.
if [ ! -f "$core_lib" ]; then
  violation "$core_lib not found"
else
  syms=$(nm -u "$core_lib" | awk '{print $NF}' | grep -E '^(MPI_|PMPI_|ompi_|H5)' | sort -u)
  [ -n "$syms" ] && violation "dem2d_core references $(wc -l <<<"$syms") MPI/HDF5 symbols: $(head -5 <<<"$syms" | tr '\n' ' ')..."
fi

# The README's tree of src/ names every room (folder) of src/ and src/core, and no other.
readme_rooms=$(awk '/^src\/$/{on=1; next} on && /^```/{exit} on' "$1/README.md" |
  sed -nE 's|^  ([a-z]+)/.*|\1|p; s|^    ([a-z]+)/.*|core/\1|p' | sort)
code_rooms=$( (cd "$src" && find . -mindepth 1 -maxdepth 1 -type d -printf '%f\n' &&
  find core -mindepth 1 -maxdepth 1 -type d) | sort)
[ "$readme_rooms" = "$code_rooms" ] ||
  violation "README.md's tree of src/ lists [$(echo $readme_rooms)], the code has [$(echo $code_rooms)]"

if [ "$failures" -gt 0 ]; then
  echo "check_layers: $failures violation(s)"
  exit 1
fi
echo "check_layers: core, parallel, io and app keep to their layers"
