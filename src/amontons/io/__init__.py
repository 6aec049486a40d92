"""Every file format the pipeline reads or writes, readers and writers side by side.

* :mod:`amontons.io.files`: atomic writes, JSON records and CSV tables (standard library only);
* :mod:`amontons.io.layout`: the raw-data layout of a sphere's folder and its file names
  (standard library only, so that the workflow's DAG is built without the numerical stack);
* :mod:`amontons.io.tiff`: microscope images with their pixel size;
* :mod:`amontons.io.heightmap`: AFM height maps (TIFF, ``.npy``, Gwyddion text);
* :mod:`amontons.io.ptu`: FLIM photons in PicoQuant PTU files (T3 image mode);
* :mod:`amontons.io.rheometer`: rheometer torque logs (our own CSV);
* :mod:`amontons.io.rheometer_export`: the rheometer programs' exports, through a column map;
* :mod:`amontons.io.units`: the one table of units an export may name;
* :mod:`amontons.io.absorbance`: absorbance spectra;
* :mod:`amontons.io.rawdata`: a sphere's raw files read with the checks the layout promises.

Every reader raises an error that names the file and says what was expected; every writer
leaves either the complete file or none.
"""
