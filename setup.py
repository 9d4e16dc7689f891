"""Setup for the fastsim_ros ament_python package."""

from glob import glob
import os

from setuptools import setup

package_name = 'fastsim_ros'

setup(
    name=package_name,
    version='0.6.0',
    packages=[package_name, package_name + '.contact', package_name + '.geometry',
              package_name + '.estimation', package_name + '.pipeline', package_name + '.cli',
              package_name + '.ros', package_name + '.replay', 'msg_adapters'],
    package_data={package_name: ['data/*.csv', 'data/profiles/*', 'data/mbench/*']},
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        (os.path.join('share', package_name, 'config'), glob('config/*.yaml')),
    ],
    install_requires=['setuptools'],
    # numba caches compiled kernels beside their module; the tables are read as files
    zip_safe=False,
    maintainer='fastsim_ros team',
    maintainer_email='fastsim@example.com',
    description=(
        'Wheel-rail creep forces with FastSim, extended to non-elliptical '
        'contact areas by MAE'
    ),
    license='Apache-2.0',
    tests_require=['pytest'],
    entry_points={
        'console_scripts': [
            'fastsim_contact = fastsim_ros.cli:main',
            'fastsim_node = fastsim_ros.ros.entry:node',
            'fastsim_lifecycle_node = fastsim_ros.ros.entry:lifecycle_node',
            'fastsim_replay = fastsim_ros.replay:main',
        ],
    },
)
