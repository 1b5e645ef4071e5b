import os
import sys

# Tests run against this checkout's package even if another checkout registered itself on sys.path.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "py"))
