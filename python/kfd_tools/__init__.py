"""kfd's Python tools: kfd-compare (compare), its statistics (stats), its judgement and
reports (report: failed runs, worst runs, verdicts) and its diagnosis of where dropped scans
cost accuracy (diagnose). Run with `python3 -m kfd_tools` or
`python3 -m kfd_tools.compare`, or through the launcher kfd-compare (scripts/kfd-compare in the
source tree, bin/kfd-compare installed), which puts this package's folder on PYTHONPATH."""
