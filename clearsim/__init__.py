"""clearsim: planar mechanisms with clearance joints."""

__version__ = "0.1.0"
