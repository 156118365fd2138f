"""`python3 -m kfd_tools ARGS` is kfd-compare ARGS."""
import sys

from kfd_tools.compare import main

sys.exit(main())
