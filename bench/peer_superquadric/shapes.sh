# shape table: tag astyle shape surf orient integrator erot a b c n1 n2
# equal volume to a sphere of r = 2 mm (V = 3.351e-8 m^3)
SHAPES=(
 "sphere|sphere|sphere|surface default|verbose no|nve/sphere|erotate/sphere|0|0|0|0|0"
 "sq22|superquadric|sq|surface superquadric|orientation random|nve/superquadric integration_scheme 1|erotate/superquadric|0.002|0.002|0.002|2.0|2.0"
 "ell2|superquadric|sq|surface superquadric|orientation random|nve/superquadric integration_scheme 1|erotate/superquadric|0.0031748021|0.0015874011|0.0015874011|2.0|2.0"
 "cube8|superquadric|sq|surface superquadric|orientation random|nve/superquadric integration_scheme 1|erotate/superquadric|0.0016458255|0.0016458255|0.0016458255|8.0|8.0"
)
