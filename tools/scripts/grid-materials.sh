# The materials and ticks make material-grid and make error-targets sweep
# (sourced): soft to stiff, compressible to nearly incompressible, light
# to heavy.  young (Pa) poisson density (kg/m^3) per entry.
# shellcheck disable=SC2034
grid_materials=(
	"2e3 0.3 110"
	"2e3 0.4999 2e4"
	"2e3 0.45 1"
	"2e5 0.4 1000"
	"2e6 0.4999 110"
	"2e7 0.3 2e4"
	"2e9 0.3 1"
	"2e9 0.4999 2e4"
)
grid_dts=(0.001 0.002)
