from glob import glob

from setuptools import find_packages, setup

package_name = 'ship_autopilot'

setup(
    name=package_name,
    version='0.1.0',
    packages=find_packages(exclude=['test']),
    data_files=[
        ('share/ament_index/resource_index/packages', ['resource/' + package_name]),
        ('share/' + package_name, ['package.xml']),
        ('share/' + package_name + '/config', glob('config/*.yaml')),
        ('share/' + package_name + '/doc', glob('doc/*.md')),
    ],
    package_data={package_name: ['data/*.yaml', 'data/policies/*.npz']},
    install_requires=['setuptools'],
    zip_safe=True,
    maintainer='Ship Navigation Maintainers',
    maintainer_email='maintainers@shipnav.org',
    description='Heading autopilots (PD, fuzzy PID, learned policy) and the autopilot node.',
    license='MIT',
    entry_points={
        'console_scripts': [
            'autopilot_node = ship_autopilot.autopilot_node:main',
        ],
    },
)
