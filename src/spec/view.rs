//! The one view type (camera, projection, viewport) that the renderer makes and the edge and line stages consume.
