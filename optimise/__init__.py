"""optimise: gradient-based design of roller ends and flanges on top of jaxbearing.

(Filled in by the gradient-design work; see the issue tracker.)
"""
