"""Speed benchmarks tracked with airspeed velocity (asv.conf.json at the top level); see
benchmarks/README.md."""
