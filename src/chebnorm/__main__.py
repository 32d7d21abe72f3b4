import sys

from chebnorm.cli import main

sys.exit(main())
